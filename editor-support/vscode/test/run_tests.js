// The TextMate grammar's tests, under node with the real engine:
//   node test/run_tests.js [--update] [--psysc PATH]
// 1. every sample (and test/showcase.psys) tokenizes exactly as test/golden/NAME.scopes says (read by eye once;
//    --update rewrites them after a deliberate change);
// 2. every word of grammar/Psys.g4 gets a keyword's scope, and the front end's keyword
//    list is exactly the grammar's words;
// 3. with --psysc: every built-in `psysc builtins` lists (functions, constants, variables,
//    types, attributes, integrators) gets its category's scope.
const fs = require("fs");
const path = require("path");
const { execFileSync } = require("child_process");
const { loadGrammar, tokenize, render } = require("./tokenize");

const root = path.join(__dirname, "..", "..", "..");
const args = process.argv.slice(2);
const update = args.includes("--update");
const psysc = args.includes("--psysc") ? args[args.indexOf("--psysc") + 1] : null;
let failures = 0;

function check(ok, what) {
    if (!ok) {
        failures++;
        console.log(`FAIL: ${what}`);
    }
}

// The scopes of `word` where it stands in `line`.
function scopeOf(grammar, line, word, nth = 1) {
    let at = -1;
    for (let i = 0; i < nth; i++) at = line.indexOf(word, at + 1);
    const token = tokenize(grammar, line)[0].find((t) => t.start <= at && at < t.start + t.text.length);
    return token ? token.scopes.join(" ") : "";
}

function goldens(grammar) {
    const samples = path.join(root, "samples");
    const golden = path.join(__dirname, "golden");
    const names = fs.readdirSync(samples).filter((f) => f.endsWith(".psys")).sort();
    // The samples, and a file with every kind of token (attributes, every number form, …).
    const files = names.map((f) => path.join(samples, f)).concat([path.join(__dirname, "showcase.psys")]);
    for (const source of files) {
        const file = path.basename(source);
        const text = fs.readFileSync(source, "utf8");
        const actual = render(text, tokenize(grammar, text));
        const goldenFile = path.join(golden, file.replace(/\.psys$/, ".scopes"));
        if (update) fs.writeFileSync(goldenFile, actual);
        const expected = fs.existsSync(goldenFile) ? fs.readFileSync(goldenFile, "utf8") : "";
        if (actual !== expected) {
            const a = actual.split("\n"), e = expected.split("\n");
            const i = a.findIndex((line, k) => line !== e[k]);
            check(false, `${file} differs from ${path.relative(root, goldenFile)} at its line ${i + 1}:\n` +
                         `  expected: ${e[i]}\n  actual:   ${a[i]}`);
        }
    }
    console.log(`goldens: ${files.length} files`);
}

function keywords(grammar) {
    const g4 = fs.readFileSync(path.join(root, "grammar", "Psys.g4"), "utf8");
    const words = [...new Set([...g4.matchAll(/'([a-z]+)'/g)].map((m) => m[1]))].sort();
    const contexts = {
        point: ["point(p, white, 1);", "point"], object: ["object o {", "object"], fn: ["fn f() = 1;", "fn"],
        trigger: ["trigger t {", "trigger"], import: ['import "a.psys";', "import"],
    };
    for (const w of words) {
        const [line, word] = contexts[w] || [`${w} x`, w];
        const s = scopeOf(grammar, line, word);
        check(/^(keyword|storage\.type|constant\.language)\./.test(s), `the grammar's word \`${w}\` gets a keyword scope (got "${s}")`);
    }
    if (psysc) {
        const frontEnd = JSON.parse(execFileSync(psysc, ["builtins"], { encoding: "utf8" })).keywords.slice().sort();
        check(JSON.stringify(frontEnd) === JSON.stringify(words),
              `the front end's keywords (${frontEnd}) are the grammar's words (${words})`);
    }
    console.log(`keywords: ${words.length} words of grammar/Psys.g4`);
}

function builtins(grammar) {
    const v = JSON.parse(execFileSync(psysc, ["builtins"], { encoding: "utf8" }));
    const cases = [
        ["functions", (f) => [`x = ${f}(1);`, f, /^support\.function\./]],
        ["constants", (c) => [`x = ${c} * 2;`, c, /^support\.constant\./]],
        ["variables", (n) => [`x = ${n} + 1;`, n, /^variable\.language\./]],
        ["types", (t) => [`extern k: ${t} = 1;`, t, /^support\.type\./]],
        ["attributes", (a) => [`@${a}(1)`, a, /^entity\.other\.attribute-name\./]],
        ["integrators", (m) => [`@integrator(${m})`, m, /^support\.constant\.integrator\./]],
    ];
    let n = 0;
    for (const [category, make] of cases) {
        for (const name of v[category]) {
            const [line, word, want] = make(name);
            const s = scopeOf(grammar, line, word, line.startsWith("x") || line.startsWith("extern") ? 1 : 1);
            check(want.test(s), `${category}: \`${name}\` in \`${line}\` gets ${want} (got "${s}")`);
            n++;
        }
    }
    console.log(`built-ins: ${n} names from psysc builtins`);
}

// The editor's idea of a word (double-click, word-based suggestions): a name or a number,
// never the operator before it (`n-1` is `n`, `-`, `1`).
function words() {
    const config = JSON.parse(fs.readFileSync(path.join(__dirname, "..", "language-configuration.json"), "utf8"));
    const pattern = new RegExp(config.wordPattern, "g");
    const cases = { "n-1": ["n", "1"], "x = -2.5e-3": ["x", "2.5e-3"], "pos.y*0.5": ["pos", "y", "0.5"] };
    for (const [text, expected] of Object.entries(cases)) {
        const actual = text.match(pattern) || [];
        check(JSON.stringify(actual) === JSON.stringify(expected),
              `the words of \`${text}\` are ${JSON.stringify(actual)}, not ${JSON.stringify(expected)}`);
    }
    console.log(`words: ${Object.keys(cases).length} cases`);
}

loadGrammar().then((grammar) => {
    words();
    goldens(grammar);
    keywords(grammar);
    if (psysc) builtins(grammar);
    if (failures) {
        console.log(`${failures} failed`);
        process.exit(1);
    }
    console.log("all passed");
});
