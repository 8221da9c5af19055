#!/usr/bin/env python3
"""Drives `psysc lsp` over stdio as an editor would, and checks what comes back.

usage: lsp_client.py PSYSC SAMPLES_DIR [--latency]

A session: initialize; open a file with an error and get its diagnostic at the right
range; fix it and get an empty list; hover a name and get its type; go to a definition
in an imported file; complete inside an object and get its equations; malformed JSON,
a header without a length and an unknown method get the protocol's errors while the
server goes on; an imported file that is not UTF-8 is a diagnostic, not a crash;
shutdown and exit with status 0. With --latency (or always, printed): the time from
an edit of the largest sample to its diagnostics."""
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time


class Client:
    def __init__(self, psysc, *args):
        self.proc = subprocess.Popen([psysc, "lsp", *args], stdin=subprocess.PIPE, stdout=subprocess.PIPE)
        self.next_id = 0
        self.pending = []  # notifications read while waiting for a response

    def raw(self, data: bytes):
        self.proc.stdin.write(data)
        self.proc.stdin.flush()

    def send(self, message):
        body = json.dumps(message).encode()
        self.raw(b"Content-Length: %d\r\n\r\n" % len(body) + body)

    def receive(self):
        header = b""
        while not header.endswith(b"\r\n\r\n"):
            c = self.proc.stdout.read(1)
            if not c:
                raise RuntimeError("the server closed its output")
            header += c
        length = int(header.split(b"Content-Length:")[1].split(b"\r\n")[0])
        return json.loads(self.proc.stdout.read(length))

    def request(self, method, params=None):
        self.next_id += 1
        self.send({"jsonrpc": "2.0", "id": self.next_id, "method": method, "params": params or {}})
        return self.response(self.next_id)

    def response(self, id):
        while True:
            m = self.receive()
            if m.get("id") == id and "method" not in m:
                return m
            self.pending.append(m)

    def notify(self, method, params):
        self.send({"jsonrpc": "2.0", "method": method, "params": params})

    def diagnostics(self, uri):
        """The next diagnostics published for `uri`."""
        while True:
            m = self.pending.pop(0) if self.pending else self.receive()
            if m.get("method") == "textDocument/publishDiagnostics" and m["params"]["uri"] == uri:
                return m["params"]


def check(condition, what):
    if not condition:
        raise AssertionError(what)
    print("ok:", what)


def uri(path):
    return "file://" + os.path.abspath(path)


def at(text, needle, shift=0):
    """The LSP position of `needle` in `text` (ASCII text)."""
    offset = text.index(needle) + shift
    line = text.count("\n", 0, offset)
    return {"line": line, "character": offset - (text.rfind("\n", 0, offset) + 1)}


def session(psysc):
    work = tempfile.mkdtemp(prefix="psys_lsp_")
    with open(os.path.join(work, "shared.psys"), "w") as f:
        f.write("// shared pieces\nfn gravity(m: float) -> vec3 = vec3(0, -9.82 * m, 0);\n")
    good = ('import "shared.psys";\n'
            "object spark(ipos: vec3) {\n"
            "    pos = snapshot(ipos) + integrate(vel);\n"
            "    vel = origin + integrate(acc);\n"
            "    acc = gravity(0.4);\n"
            "    point(pos, mix(green, black, age), 2);\n"
            "    kill when age > 1;\n"
            "}\n"
            "spawn spark(origin);\n")
    bad = good.replace("integrate(acc)", "integrate(acx)")
    main = os.path.join(work, "main.psys")
    with open(main, "w") as f:
        f.write(good)

    c = Client(psysc)
    init = c.request("initialize", {"processId": os.getpid(), "rootUri": uri(work), "capabilities": {}})
    caps = init["result"]["capabilities"]
    check(caps["hoverProvider"] and caps["definitionProvider"] and caps["documentSymbolProvider"],
          "initialize announces hover, definition and symbols")
    c.notify("initialized", {})

    c.notify("textDocument/didOpen", {"textDocument": {"uri": uri(main), "languageId": "psys", "version": 1, "text": bad}})
    d = c.diagnostics(uri(main))
    check(len(d["diagnostics"]) == 1, "a file with an error gets one diagnostic")
    diag = d["diagnostics"][0]
    check(diag["range"] == {"start": at(bad, "acx"), "end": at(bad, "acx", 3)},
          "the diagnostic covers `acx` exactly: %s" % json.dumps(diag["range"]))
    check("acx" in diag["message"] and "did you mean `acc`" in diag["message"], "it names the unknown name and suggests `acc`")

    c.notify("textDocument/didChange", {"textDocument": {"uri": uri(main), "version": 2}, "contentChanges": [{"text": good}]})
    d = c.diagnostics(uri(main))
    check(d["diagnostics"] == [] and d["version"] == 2, "fixing it publishes an empty list")

    h = c.request("textDocument/hover", {"textDocument": {"uri": uri(main)}, "position": at(good, "vel);")})
    check("vel: vec3" in h["result"]["contents"]["value"], "hover on `vel` gives its type: vec3")

    r = c.request("textDocument/definition", {"textDocument": {"uri": uri(main)}, "position": at(good, "gravity", 2)})
    loc = r["result"]
    check(loc["uri"] == uri(os.path.join(work, "shared.psys")) and loc["range"]["start"] == {"line": 1, "character": 3},
          "definition of `gravity` is in the imported file, line 2")

    r = c.request("textDocument/completion", {"textDocument": {"uri": uri(main)}, "position": at(good, "point(")})
    labels = [i["label"] for i in r["result"]["items"]]
    check(all(n in labels for n in ("pos", "vel", "acc", "ipos")), "completion inside the object lists its equations")

    r = c.request("textDocument/documentSymbol", {"textDocument": {"uri": uri(main)}})
    check([s["name"] for s in r["result"]] == ["spark"] and
          [s["name"] for s in r["result"][0]["children"]] == ["ipos", "pos", "vel", "acc"], "document symbols")

    # What a broken client may send: the server answers with the protocol's errors and goes on.
    c.raw(b"Content-Length: 9\r\n\r\n{not json")
    m = c.receive()
    check(m["error"]["code"] == -32700 and m["id"] is None, "malformed JSON gets a parse error")
    c.raw(b"X-Nothing: 1\r\n\r\n")
    check(c.receive()["error"]["code"] == -32700, "a header without Content-Length gets a parse error")
    check(c.request("psys/frobnicate")["error"]["code"] == -32601, "an unknown method gets MethodNotFound")
    c.send({"jsonrpc": "2.0", "id": "s", "method": "textDocument/hover", "params": {"textDocument": 3}})
    check(c.response("s")["error"]["code"] == -32602, "bad params get InvalidParams")
    c.send({"jsonrpc": "1.0", "id": 99, "method": "initialize"})
    check(c.response(99)["error"]["code"] == -32600, "a message that is not JSON-RPC 2.0 gets InvalidRequest")

    # An imported file that is not UTF-8: a diagnostic, and the server stays up.
    with open(os.path.join(work, "latin1.psys"), "wb") as f:
        f.write(b"// caf\xe9\nconst k = 1;\n")
    latin = 'import "latin1.psys";\nobject o { point(vec3(k), white, 1); }\nspawn o;\n'
    other = os.path.join(work, "other.psys")
    c.notify("textDocument/didOpen", {"textDocument": {"uri": uri(other), "languageId": "psys", "version": 1, "text": latin}})
    d = c.diagnostics(uri(os.path.join(work, "latin1.psys")))
    check(len(d["diagnostics"]) == 1 and "not valid UTF-8" in d["diagnostics"][0]["message"] and
          d["diagnostics"][0]["range"]["start"] == {"line": 0, "character": 6},
          "an imported file that is not UTF-8 gets a diagnostic at its bad byte")
    check(c.request("shutdown")["result"] is None, "shutdown")
    c.notify("exit", {})
    check(c.proc.wait(timeout=10) == 0, "exit after shutdown ends the server with status 0")


def latency(psysc, samples, debounce):
    """Median milliseconds from an edit of the largest sample to its diagnostics."""
    largest = max((os.path.join(samples, f) for f in os.listdir(samples) if f.endswith(".psys")), key=os.path.getsize)
    text = open(largest).read()
    c = Client(psysc, "--debounce", str(debounce))
    c.request("initialize", {"capabilities": {}})
    c.notify("textDocument/didOpen", {"textDocument": {"uri": uri(largest), "languageId": "psys", "version": 1, "text": text}})
    c.diagnostics(uri(largest))
    clean, broken = [], []
    for v in range(2, 42):
        edited = text + ("\n// edit %d\n" % v if v % 2 else "\nconst broken = ;\n")
        start = time.perf_counter()
        c.notify("textDocument/didChange", {"textDocument": {"uri": uri(largest), "version": v}, "contentChanges": [{"text": edited}]})
        d = c.diagnostics(uri(largest))
        (clean if v % 2 else broken).append((time.perf_counter() - start) * 1000)
        assert (len(d["diagnostics"]) > 0) == (v % 2 == 0)
    c.request("shutdown")
    c.notify("exit", {})
    c.proc.wait(timeout=10)
    return os.path.basename(largest), os.path.getsize(largest), clean, broken


if __name__ == "__main__":
    psysc, samples = sys.argv[1], sys.argv[2]
    session(psysc)
    for debounce in (0, 150):
        name, size, clean, broken = latency(psysc, samples, debounce)
        for what, times in (("a clean edit (front end and passes)", clean), ("a syntax error", broken)):
            print("latency: %s (%d bytes), debounce %d ms, %s: edit to diagnostics median %.1f ms, worst %.1f ms "
                  "(%d edits)" % (name, size, debounce, what, statistics.median(times), max(times), len(times)))
