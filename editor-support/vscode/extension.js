// Starts `psysc lsp` for .psys files: diagnostics, hover, go to definition, symbols and
// completion come from the compiler's own front end. psysc is found through the
// `psys.server.path` setting (a path, or a name looked up on PATH).
const vscode = require("vscode");
const { LanguageClient, TransportKind } = require("vscode-languageclient/node");

let client;

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
            `psys: cannot start \`${command} lsp\` (${e.message}). Set psys.server.path to the psysc executable.`);
    }
}

function activate(context) {
    start();
    context.subscriptions.push(vscode.workspace.onDidChangeConfiguration(async (event) => {
        if (!event.affectsConfiguration("psys.server")) return;
        if (client) await client.stop();
        start();
    }));
}

function deactivate() {
    return client ? client.stop() : undefined;
}

module.exports = { activate, deactivate };
