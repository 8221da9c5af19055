// Tokenizes .psys text with the real TextMate engine VS Code uses (vscode-textmate over
// the Oniguruma regex library compiled to WebAssembly) and our grammar.
const fs = require("fs");
const path = require("path");
let vsctm, oniguruma;
try {
    vsctm = require("vscode-textmate");
    oniguruma = require("vscode-oniguruma");
} catch (e) {
    console.error("vscode-textmate is not installed: run scripts/setup.sh (npm ci in editor-support/vscode)");
    process.exit(1);
}

const grammarPath = path.join(__dirname, "..", "syntaxes", "psys.tmLanguage.json");

async function loadGrammar() {
    const wasm = fs.readFileSync(require.resolve("vscode-oniguruma/release/onig.wasm"));
    await oniguruma.loadWASM(wasm.buffer.slice(wasm.byteOffset, wasm.byteOffset + wasm.byteLength));
    const registry = new vsctm.Registry({
        onigLib: Promise.resolve({
            createOnigScanner: (patterns) => new oniguruma.OnigScanner(patterns),
            createOnigString: (s) => new oniguruma.OnigString(s),
        }),
        loadGrammar: async (scopeName) =>
            scopeName === "source.psys"
                ? vsctm.parseRawGrammar(fs.readFileSync(grammarPath, "utf8"), grammarPath)
                : null,
    });
    return registry.loadGrammar("source.psys");
}

// Lines of tokens: [{text, scopes}] per line, scopes without the root `source.psys`.
function tokenize(grammar, text) {
    let state = vsctm.INITIAL;
    return text.split(/\r?\n/).map((line) => {
        const result = grammar.tokenizeLine(line, state);
        state = result.ruleStack;
        return result.tokens.map((t) => ({
            start: t.startIndex,
            text: line.substring(t.startIndex, t.endIndex),
            scopes: t.scopes.slice(1),
        }));
    });
}

// The golden form: each line, then each of its tokens that is not blank with its scopes.
function render(text, lines) {
    const source = text.split(/\r?\n/);
    let out = "";
    lines.forEach((tokens, i) => {
        if (source[i] === "" && i === source.length - 1) return;
        out += `${i + 1}: ${source[i]}\n`;
        for (const t of tokens) {
            if (t.text.trim() === "") continue;
            out += `    ${t.start}: ${JSON.stringify(t.text)} ${t.scopes.join(" ") || "-"}\n`;
        }
    });
    return out;
}

module.exports = { loadGrammar, tokenize, render };
