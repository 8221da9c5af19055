// The extension under a stand-in host: `vscode` and the language client replaced by
// fakes that record what the extension does. A start that fails (psysc not found) shows
// the failure's own words, and changing psys.server.path then starts the server again.
const Module = require("module");
const path = require("path");
const assert = require("assert");

const log = { messages: [], starts: [], stops: 0, disposes: 0 };
let configListener;
let settings = { "server.path": "/nowhere/psysc", "server.debounceMs": 150 };

class FakeClient {
    constructor(id, name, server) {
        this.command = server.run.command;
        this.running = false;
    }
    async start() {
        log.starts.push(this.command);
        if (this.command.startsWith("/nowhere")) {
            // What vscode-languageclient throws for a missing executable: no message of its own.
            throw { code: "ENOENT", toString: () => `spawn ${this.command} ENOENT` };
        }
        this.running = true;
    }
    isRunning() { return this.running; }
    async stop() {
        if (!this.running) throw new Error("Client is not running and can't be stopped. It's current state is: startFailed");
        log.stops++;
        this.running = false;
    }
    async dispose() { log.disposes++; }
}

const fakeVscode = {
    workspace: {
        getConfiguration: () => ({ get: (key, fallback) => (key in settings ? settings[key] : fallback) }),
        createFileSystemWatcher: () => ({}),
        onDidChangeConfiguration: (listener) => { configListener = listener; return { dispose() {} }; },
    },
    window: { showErrorMessage: (m) => log.messages.push(m) },
};
const fakes = {
    vscode: fakeVscode,
    "vscode-languageclient/node": { LanguageClient: FakeClient, TransportKind: { stdio: 0 } },
};
const load = Module._load;
Module._load = function (request, parent, isMain) {
    if (request in fakes) return fakes[request];
    return load.apply(this, arguments);
};

(async () => {
    const extension = require(path.join(__dirname, "..", "extension.js"));
    const context = { subscriptions: [] };
    extension.activate(context);
    await new Promise((r) => setImmediate(r));
    assert.deepStrictEqual(log.starts, ["/nowhere/psysc"]);
    assert.strictEqual(log.messages.length, 1);
    assert.ok(!log.messages[0].includes("undefined"), log.messages[0]);
    assert.ok(log.messages[0].includes("ENOENT"), log.messages[0]);

    // The user fixes the path: the failed client is put away, a new one starts.
    settings["server.path"] = "/usr/bin/psysc";
    await configListener({ affectsConfiguration: (s) => s === "psys.server" });
    assert.deepStrictEqual(log.starts, ["/nowhere/psysc", "/usr/bin/psysc"]);
    assert.strictEqual(log.messages.length, 1);

    // Another change stops the running one first.
    settings["server.debounceMs"] = 300;
    await configListener({ affectsConfiguration: (s) => s === "psys.server" });
    assert.strictEqual(log.stops, 1);
    assert.strictEqual(log.starts.length, 3);
    await extension.deactivate();
    assert.strictEqual(log.stops, 2);
    console.log("extension: a failed start shows its reason and a settings change restarts the server");
})().catch((e) => {
    console.error(e);
    process.exit(1);
});
