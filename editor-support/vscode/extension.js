// Starts `psysc lsp` for .psys files: diagnostics, hover, go to definition, symbols and
// completion come from the compiler's own front end. psysc is found through the
// `psys.server.path` setting (a path, or a name looked up on PATH); changing a
// `psys.server` setting restarts the server, also after a start that failed.
const vscode = require("vscode");
const { LanguageClient, TransportKind } = require("vscode-languageclient/node");

let client;

// What a failure says: an Error's message, else whatever was thrown, as text.
function reason(e) {
    if (e && typeof e.message === "string" && e.message) return e.message;
    return String(e);
}

async function start() {
    const config = vscode.workspace.getConfiguration("psys");
    const command = config.get("server.path", "psysc");
    const debounce = String(config.get("server.debounceMs", 150));
    const run = { command, args: ["lsp", "--debounce", debounce], transport: TransportKind.stdio };
    client = new LanguageClient("psys", "psys language server", { run, debug: run }, {
        documentSelector: [{ language: "psys" }],
        synchronize: { fileEvents: vscode.workspace.createFileSystemWatcher("**/*.psys") },
    });
    try {
        await client.start();
    } catch (e) {
        vscode.window.showErrorMessage(
            `psys: cannot start \`${command} lsp\` (${reason(e)}). Set psys.server.path to the psysc executable.`);
    }
}

// A client that never started (a wrong path) has nothing to stop: stopping it throws,
// which must not keep the next start from running.
async function stop() {
    const old = client;
    client = undefined;
    if (!old) return;
    try {
        if (typeof old.isRunning !== "function" || old.isRunning()) await old.stop();
        else if (typeof old.dispose === "function") await old.dispose();
    } catch (e) {
        // (already stopped, or never started)
    }
}

function activate(context) {
    start();
    context.subscriptions.push(vscode.workspace.onDidChangeConfiguration(async (event) => {
        if (!event.affectsConfiguration("psys.server")) return;
        await stop();
        await start();
    }));
}

function deactivate() {
    return stop();
}

module.exports = { activate, deactivate };
