// The language server's features on real analyses (hover, definition across an import,
// symbols, completion, diagnostics with their ranges), its positions in UTF-16, and its
// protocol: every malformed or out-of-order message gets the protocol's error.
#define DOCTEST_CONFIG_IMPLEMENT_WITH_MAIN
#include <doctest/doctest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "lsp/analysis.h"
#include "lsp/features.h"
#include "lsp/positions.h"
#include "lsp/recover.h"
#include "lsp/server.h"
#include "lsp/transport.h"
#include "lsp_support.h"

using namespace psys;
using namespace psys::lsp;
using namespace psys::lsp::test;
using nlohmann::json;


TEST_CASE("hover: an equation, a parameter, a built-in, a swizzle, a live parent read, an extern") {
    std::string text = kFireworks;
    Analysis a = analyze("/tmp/fw.psys", text);
    REQUIRE(a.parsed);
    CHECK(a.diagnostics.empty());
    CHECK(hoverText(a, at(text, "pos =")) == "```psys\npos: vec3\n```\n\nequation of `rocket`");
    CHECK(hoverText(a, at(text, "ivel)", 1, 2)) == "```psys\nivel: vec3\n```\n\nparameter of `rocket`");
    CHECK(hoverText(a, at(text, "integrate(vel)")).find("integrate(x: T) -> T") != std::string::npos);
    CHECK(hoverText(a, at(text, "vel.y", 1, 4)) == "```psys\n.y: float\n```\n\nswizzle");
    CHECK(hoverText(a, at(text, "rocket.vel", 1, 8)).find("vel: vec3") != std::string::npos);
    CHECK(hoverText(a, at(text, "rocket.vel", 1, 8)).find("read live from `rocket`") != std::string::npos);
    CHECK(hoverText(a, at(text, "sparks per")) == "```psys\nextern sparks: float\n```\n\nset by the host");
    CHECK(hoverText(a, at(text, "gravity(0.3)")) == "```psys\nfn gravity(m: float) -> vec3\n```");
    CHECK(hoverText(a, at(text, "white")).find("built-in constant (1, 1, 1, 1)") != std::string::npos);
    CHECK(hoverText(a, at(text, "age > 1")).find("age: float") != std::string::npos);
    // An expression that is not a name shows its type: `vel.y < 0` is a bool.
    CHECK(hoverText(a, at(text, "< 0")) == "```psys\nbool\n```");
    CHECK(hoverText(a, at(text, "spawn", 1, 1)).empty());
}

TEST_CASE("definition: an equation, a parent read, an emitted object, a function") {
    std::string text = kFireworks;
    Analysis a = analyze("/tmp/fw.psys", text);
    auto target = [&](uint32_t offset) {
        json d = definition(a, offset);
        REQUIRE(!d.is_null());
        CHECK(d["uri"] == "file:///tmp/fw.psys");
        return d["range"]["start"];
    };
    CHECK(target(at(text, "integrate(vel)", 1, 10)) == json{{"line", 4}, {"character", 4}});
    CHECK(target(at(text, "rocket.vel", 1, 8)) == json{{"line", 4}, {"character", 4}});
    CHECK(target(at(text, "rocket.vel", 1, 1)) == json{{"line", 2}, {"character", 7}});
    CHECK(target(at(text, "spark(pos)")) == json{{"line", 8}, {"character", 11}});
    CHECK(target(at(text, "gravity(0.3)")) == json{{"line", 1}, {"character", 3}});
    CHECK(definition(a, at(text, "age > 1")).is_null());  // built-in: nowhere to go
}

TEST_CASE("definition across an import, and the imported file's diagnostics go to its own URI") {
    TempDir dir;
    dir.write("lib.psys", "// shared\nfn wobble(x: float) -> float = sin(x * 3);\nconst lift = 2;\n");
    std::string main = "import \"lib.psys\";\nobject o { y = wobble(age) * lift; point(vec3(0, y, 0), white, 1); }\nspawn o;\n";
    Analysis a = analyze(dir.write("main.psys", main), main);
    REQUIRE(a.parsed);
    json d = definition(a, at(main, "wobble"));
    CHECK(d["uri"] == uriFromPath((dir.path / "lib.psys").string()));
    CHECK(d["range"]["start"] == json{{"line", 1}, {"character", 3}});
    CHECK(definition(a, at(main, "lift"))["range"]["start"] == json{{"line", 2}, {"character", 6}});
    json import = definition(a, at(main, "lib.psys"));
    CHECK(import["uri"] == uriFromPath((dir.path / "lib.psys").string()));

    dir.write("lib.psys", "fn wobble(x: float) -> float = sin(x * 3) + nope;\nconst lift = 2;\n");
    Analysis broken = analyze((dir.path / "main.psys").string(), main);
    auto byUri = diagnosticsByUri(broken);
    json libDiagnostics = byUri[uriFromPath((dir.path / "lib.psys").string())];
    REQUIRE(libDiagnostics.size() == 1);
    CHECK(libDiagnostics[0]["message"].get<std::string>().find("nope") != std::string::npos);
    // And at the main file's import line, where the editor is (psysc check of it fails).
    json mainDiagnostics = byUri[uriFromPath((dir.path / "main.psys").string())];
    REQUIRE(mainDiagnostics.size() == 1);
    CHECK(mainDiagnostics[0]["range"]["start"] == json{{"line", 0}, {"character", 7}});
    CHECK(mainDiagnostics[0]["severity"] == 1);
    CHECK(mainDiagnostics[0]["message"].get<std::string>().find("lib.psys:1:45: unknown name `nope`") != std::string::npos);
    CHECK(mainDiagnostics[0]["relatedInformation"][0]["location"]["uri"] == uriFromPath((dir.path / "lib.psys").string()));

    // A syntax error two imports down shows at the main file's import of the first.
    dir.write("lib.psys", "import \"deep.psys\";\nfn wobble(x: float) -> float = x;\nconst lift = 2;\n");
    dir.write("deep.psys", "fn f(x: float) -> float = (x;\n");
    Analysis deep = analyze((dir.path / "main.psys").string(), main);
    json shown = diagnosticsByUri(deep)[uriFromPath((dir.path / "main.psys").string())];
    REQUIRE(shown.size() == 1);
    CHECK(shown[0]["range"]["start"] == json{{"line", 0}, {"character", 7}});
    CHECK(shown[0]["message"].get<std::string>().find("deep.psys:1:29") != std::string::npos);
}

TEST_CASE("hover on an integrator's name says what the method computes, its order and its stability") {
    std::string text = "@integrator(rk4)\nobject o { x = integrate(1); point(vec3(x), white, 1); }\n"
                       "@integrator(semi_implicit)\nobject p { point(vec3(0), white, 1); }\n"
                       "@integrator(leapfrog)\nobject q { point(vec3(0), white, 1); }\nspawn o;\nspawn p;\n";
    Analysis a = analyze("/tmp/int.psys", text);
    REQUIRE(a.parsed);
    std::string rk4 = hoverText(a, at(text, "rk4", 1, 1));
    CHECK(rk4.find("@integrator(rk4)") != std::string::npos);
    CHECK(rk4.find("order 4") != std::string::npos);
    CHECK(rk4.find("2.785") != std::string::npos);
    CHECK(hoverText(a, at(text, "semi_implicit", 1, 2)).find("the default") != std::string::npos);
    std::string leapfrog = hoverText(a, at(text, "leapfrog", 1, 1));
    CHECK(leapfrog.find("velocity Verlet") != std::string::npos);
    CHECK(leapfrog.find("order 2") != std::string::npos);
}

TEST_CASE("an imported file changed on disk: the open documents are analysed again (didChangeWatchedFiles)") {
    TempDir dir;
    dir.write("lib.psys", "const lift = 2;\n");
    std::string main = "import \"lib.psys\";\nobject o { point(vec3(0, lift, 0), white, 1); }\nspawn o;\n";
    std::string path = dir.write("main.psys", main);
    std::vector<json> out;
    Server server(exactReads(), [&](const json& m) { out.push_back(m); });
    server.handle({{"jsonrpc", "2.0"}, {"id", 1}, {"method", "initialize"}, {"params", json::object()}});
    server.handle({{"jsonrpc", "2.0"}, {"method", "textDocument/didOpen"},
                   {"params", {{"textDocument", {{"uri", uriFromPath(path)}, {"version", 1}, {"text", main}}}}}});
    out.clear();
    dir.write("lib.psys", "const lyft = 2;\n");
    server.handle({{"jsonrpc", "2.0"}, {"method", "workspace/didChangeWatchedFiles"},
                   {"params", {{"changes", {{{"uri", uriFromPath((dir.path / "lib.psys").string())}, {"type", 2}}}}}}});
    server.idle();  // starts the analysis in the background
    server.settle();
    size_t errors = 0;
    for (const json& m : out)
        if (m.value("method", "") == "textDocument/publishDiagnostics" && m["params"]["uri"] == uriFromPath(path))
            errors += m["params"]["diagnostics"].size();
    CHECK(errors == 1);  // `lift` is unknown now
}

TEST_CASE("definition into the standard library: an `std/` import and its functions") {
    TempDir dir;
    std::string main = "import \"std/shapes.psys\";\nobject o(q: vec3) { point(snapshot(q), white, 1); }\n"
                       "object e { emit o(in_sphere(2)) count 3; }\nspawn e;\n";
    Analysis a = analyze(dir.write("main.psys", main), main);
    REQUIRE(a.parsed);
    json file = definition(a, at(main, "std/shapes.psys"));
    CHECK(file["uri"].get<std::string>().find("/std/shapes.psys") != std::string::npos);
    json fn = definition(a, at(main, "in_sphere"));
    CHECK(fn["uri"] == file["uri"]);
}

TEST_CASE("completion: names in scope inside an object, members after a dot, attributes after @") {
    std::string text = kFireworks;
    Analysis a = analyze("/tmp/fw.psys", text);
    auto inRocket = labels(completion(a, text, at(text, "point(pos, white")));
    for (const char* n : {"pos", "vel", "ivel", "spark", "sparks", "gravity", "integrate", "age", "white", "emit", "vec3"})
        CHECK_MESSAGE(has(inRocket, n), n);
    CHECK_FALSE(has(inRocket, "ipos"));  // spark's parameter is not in rocket's scope
    auto inSpark = labels(completion(a, text, at(text, "point(pos, mix")));
    CHECK(has(inSpark, "ipos"));
    CHECK(has(inSpark, "rocket"));  // an enclosing object, read live
    std::string dotted = text;
    uint32_t cursor = at(dotted, "rocket.vel", 1, 7);
    auto members = labels(completion(a, dotted, cursor));
    CHECK(members == std::vector<std::string>{"alive", "age", "ivel", "pos", "vel"});
    std::string attr = "@\n" + text;
    CHECK(labels(completion(a, attr, 1)) == std::vector<std::string>{"integrator", "step", "tolerance", "precision", "capacity", "shape", "texture", "blend"});
    std::string integrator = "@integrator(\n" + text;
    CHECK(has(labels(completion(a, integrator, 12)), "rk4"));
    std::string precision = "@precision(\n" + text;
    CHECK(labels(completion(a, precision, 11)) == std::vector<std::string>{"float", "double"});
}

TEST_CASE("diagnostics: ranges in UTF-16, notes as related information, warnings, syntax errors") {
    // é is 2 bytes and 1 UTF-16 unit, 𝄞 4 bytes and 2 units: the error's column in UTF-16 is 3 less than in bytes.
    std::string text = "object o { /* é𝄞 */ x = vec3(1) + vec2(1); point(vec3(0), white, 1); }\nspawn o;\n";
    Analysis a = analyze("/tmp/d.psys", text);
    json diags = diagnosticsByUri(a)["file:///tmp/d.psys"];
    REQUIRE(diags.size() == 1);
    CHECK(diags[0]["severity"] == 1);
    CHECK(diags[0]["message"] == "cannot add vec3 and vec2: vectors of different sizes");
    // The operands that disagree: from `vec3(1)` to the end of `vec2(1)`.
    uint32_t begin = at(text, "vec3(1)"), end = at(text, "vec2(1)") + 7;
    CHECK(diags[0]["range"]["start"] == json{{"line", 0}, {"character", begin - 3}});
    CHECK(diags[0]["range"]["end"] == json{{"line", 0}, {"character", end - 3}});

    Analysis unused = analyze("/tmp/u.psys", "object o { p = 1; point(vec3(0), white, 1); }\nspawn o;\n");
    json w = diagnosticsByUri(unused)["file:///tmp/u.psys"];
    REQUIRE(w.size() == 1);
    CHECK(w[0]["severity"] == 2);
    CHECK(w[0]["message"] == "equation `p` is never used");

    Analysis notes = analyze("/tmp/n.psys", "object o { x = 1; x = 2; point(vec3(x), white, 1); }\nspawn o;\n");
    json n = diagnosticsByUri(notes)["file:///tmp/n.psys"];
    REQUIRE(n.size() == 1);
    REQUIRE(n[0].contains("relatedInformation"));
    CHECK(n[0]["relatedInformation"][0]["location"]["range"]["start"] == json{{"line", 0}, {"character", 11}});

    Analysis syntax = analyze("/tmp/s.psys", "object o { x = ; }\n");
    CHECK_FALSE(syntax.parsed);
    json s = diagnosticsByUri(syntax)["file:///tmp/s.psys"];
    REQUIRE(s.size() == 1);
    CHECK(s[0]["range"]["start"] == json{{"line", 0}, {"character", 15}});
    CHECK(hover(syntax, 12).is_null());
}

TEST_CASE("positions: UTF-16 columns to bytes and back — URIs with spaces") {
    SourceFile f("x", "a𝄞b\né=1\n");
    CHECK(position(f, 5) == json{{"line", 0}, {"character", 3}});  // after the 4-byte 𝄞: 2 UTF-16 units
    CHECK(offsetOf(f, json{{"line", 0}, {"character", 3}}) == 5);
    CHECK(offsetOf(f, json{{"line", 1}, {"character", 1}}) == 9);   // é is 2 bytes, 1 unit
    CHECK(offsetOf(f, json{{"line", 1}, {"character", 99}}) == 11);  // clamped to the line
    CHECK(offsetOf(f, json{{"line", 9}, {"character", 0}}) == f.text().size());
    CHECK(pathFromUri("file:///a%20b/c.psys") == "/a b/c.psys");
    CHECK(uriFromPath("/a b/c.psys") == "file:///a%20b/c.psys");
}

TEST_CASE("positions: on a long line of mixed widths, every column maps as a scan from the line's start maps it") {
    // 10,000 characters of 1-, 2-, 3- and 4-byte sequences on the second line: SourceFile's
    // running count (checkpoints every 64 bytes) against the plain scan, both ways.
    const char* pieces[] = {"a", "é", "€", "𝄞"};
    std::string line;
    for (int i = 0; i < 10000; ++i) line += pieces[(i * 7 + i / 13) % 4];
    SourceFile f("x", "first\n" + line + "\nlast\n");
    uint32_t start = 6, units = 0;
    for (uint32_t at = start; at <= start + line.size(); ++at) {
        bool boundary = at == start + line.size() || (static_cast<unsigned char>(f.text()[at]) & 0xC0) != 0x80;
        if (boundary) {
            REQUIRE(position(f, at) == json{{"line", 1}, {"character", units}});
            REQUIRE(offsetOf(f, json{{"line", 1}, {"character", units}}) == at);
        }
        if (at < start + line.size()) {
            auto c = static_cast<unsigned char>(f.text()[at]);
            units += (c & 0xC0) == 0x80 ? 0 : c >= 0xF0 ? 2 : 1;
        }
    }
    CHECK(offsetOf(f, json{{"line", 1}, {"character", units + 5}}) == start + line.size());  // clamped to the line
}

TEST_CASE("positions: a line or column past any file (1e300, 2^64) is clamped, a negative or non-numeric one refused") {
    SourceFile f("x", "ab\ncd\n");
    CHECK(offsetOf(f, json{{"line", 1e300}, {"character", 0}}) == f.text().size());
    CHECK(offsetOf(f, json{{"line", 18446744073709551615ull}, {"character", 18446744073709551615ull}}) == f.text().size());
    CHECK(offsetOf(f, json{{"line", 0}, {"character", 1e300}}) == 2);
    CHECK_THROWS_WITH(offsetOf(f, json{{"line", -1}, {"character", 0}}), doctest::Contains("a count from 0, not -1"));
    CHECK_THROWS_WITH(offsetOf(f, json{{"line", "two"}, {"character", 0}}), doctest::Contains("not \"two\""));
}


TEST_CASE("protocol: errors for requests before initialize, unknown methods, bad params, after shutdown") {
    Session s;
    CHECK(s.request(1, "textDocument/hover")["error"]["code"] == error::kServerNotInitialized);
    // A debounce that is not a whole number of milliseconds in range: refused, and the
    // server not initialised by it.
    for (json bad : {json(1.5), json(-3), json(1e300), json("soon"), json(600001)})
        CHECK(s.request(2, "initialize", {{"initializationOptions", {{"debounceMs", bad}}}})["error"]["code"] ==
              error::kInvalidParams);
    CHECK(s.request(2, "initialize")["result"]["capabilities"]["hoverProvider"] == true);
    CHECK(s.request(3, "initialize")["error"]["code"] == error::kInvalidRequest);
    CHECK(s.request(4, "no/such/method")["error"]["code"] == error::kMethodNotFound);
    CHECK(s.request(5, "textDocument/hover", {{"textDocument", 7}})["error"]["code"] == error::kInvalidParams);
    CHECK(s.request(6, "textDocument/hover", {{"textDocument", {{"uri", "file:///closed.psys"}}},
                                               {"position", {{"line", 0}, {"character", 0}}}})["error"]["code"] ==
          error::kInvalidParams);
    s.out.clear();
    s.server.handle(json::array({1, 2}));
    REQUIRE(s.out.size() == 1);
    CHECK(s.out[0]["error"]["code"] == error::kInvalidRequest);
    s.out.clear();
    s.server.handle({{"jsonrpc", 2}, {"id", 9}, {"method", "initialize"}});  // not the string "2.0"
    REQUIRE(s.out.size() == 1);
    CHECK(s.out[0]["error"]["code"] == error::kInvalidRequest);
    s.out.clear();
    s.server.handle({{"jsonrpc", "2.0"}, {"method", "$/unknownNotification"}});
    CHECK(s.out.empty());  // an unknown notification is ignored
    CHECK(s.request(7, "shutdown")["result"].is_null());
    CHECK(s.request(8, "textDocument/documentSymbol")["error"]["code"] == error::kInvalidRequest);
    s.server.handle({{"jsonrpc", "2.0"}, {"method", "exit"}});
    CHECK(s.server.exitCode() == 0);
}

TEST_CASE("documents: edits are debounced, requests see the latest text, closing clears diagnostics") {
    Session s;
    s.request(1, "initialize", {{"initializationOptions", {{"debounceMs", 60000}}}});
    std::string uri = "file:///tmp/doc.psys";
    s.out.clear();
    s.server.handle({{"jsonrpc", "2.0"}, {"method", "textDocument/didOpen"},
                     {"params", {{"textDocument", {{"uri", uri}, {"version", 1}, {"text", "const a = 1 +;\n"}}}}}});
    REQUIRE(s.out.size() == 1);
    CHECK(s.out[0]["params"]["diagnostics"].size() == 1);
    s.out.clear();
    // An incremental edit: `1 +` becomes `1 + 2`.
    s.server.handle({{"jsonrpc", "2.0"}, {"method", "textDocument/didChange"},
                     {"params", {{"textDocument", {{"uri", uri}, {"version", 2}}},
                                 {"contentChanges", {{{"range", {{"start", {{"line", 0}, {"character", 13}}},
                                                                 {"end", {{"line", 0}, {"character", 13}}}}},
                                                      {"text", " 2"}}}}}}});
    s.server.idle();
    CHECK(s.out.empty());  // still within the debounce interval
    CHECK(s.server.nextDeadline().has_value());
    json h = s.request(2, "textDocument/hover", {{"textDocument", {{"uri", uri}}}, {"position", {{"line", 0}, {"character", 6}}}});
    CHECK(h["result"]["contents"]["value"] == "```psys\nconst a: float\n```");
    bool cleared = false;
    for (const json& m : s.out)
        if (m.value("method", "") == "textDocument/publishDiagnostics")
            cleared = m["params"]["diagnostics"].empty() && m["params"]["version"] == 2;
    CHECK(cleared);
    CHECK_FALSE(s.server.nextDeadline().has_value());
    s.out.clear();
    s.server.handle({{"jsonrpc", "2.0"}, {"method", "textDocument/didClose"}, {"params", {{"textDocument", {{"uri", uri}}}}}});
    REQUIRE(s.out.size() == 1);
    CHECK(s.out[0]["params"]["diagnostics"].empty());
}

TEST_CASE("transport: framing, a header without a length, text that is not JSON, the end of input") {
    int fds[2];
    REQUIRE(pipe(fds) == 0);
    std::string body = R"({"jsonrpc":"2.0","method":"x"})";
    std::string input = "Content-Length: " + std::to_string(body.size()) + "\r\n\r\n" + body +
                        "Content-Type: x\r\n\r\n" + "content-length: 5\r\n\r\n{nope";
    REQUIRE(write(fds[1], input.data(), input.size()) == static_cast<ssize_t>(input.size()));
    close(fds[1]);
    Transport t(fds[0], -1);
    Incoming m = t.read(std::nullopt);
    CHECK(m.kind == Incoming::Kind::Message);
    CHECK(m.json["method"] == "x");
    CHECK(t.read(std::nullopt).kind == Incoming::Kind::Malformed);
    Incoming bad = t.read(std::nullopt);
    CHECK(bad.kind == Incoming::Kind::Malformed);
    CHECK(bad.problem == "the message is not JSON");
    CHECK(t.read(std::nullopt).kind == Incoming::Kind::End);
    close(fds[0]);
}

TEST_CASE("transport: a stray newline, a NUL or a header without a length between messages costs one error, not the rest") {
    int fds[2];
    REQUIRE(pipe(fds) == 0);
    auto frame = [](const std::string& method) {
        std::string body = R"({"jsonrpc":"2.0","method":")" + method + R"("})";
        return "Content-Length: " + std::to_string(body.size()) + "\r\n\r\n" + body;
    };
    std::string input = frame("a") + "\n" + frame("b") + std::string(1, '\0') + frame("c") +
                        "Content-Type: x\r\n\r\n" + frame("d") + "\r\n" + frame("e");
    REQUIRE(write(fds[1], input.data(), input.size()) == static_cast<ssize_t>(input.size()));
    close(fds[1]);
    Transport t(fds[0], -1);
    std::string methods;
    int malformed = 0;
    for (Incoming m = t.read(std::nullopt); m.kind != Incoming::Kind::End; m = t.read(std::nullopt)) {
        if (m.kind == Incoming::Kind::Message) methods += m.json["method"].get<std::string>();
        malformed += m.kind == Incoming::Kind::Malformed;
    }
    CHECK(methods == "abcde");
    CHECK(malformed == 3);  // (a blank line before a header is no error)
    close(fds[0]);
}

TEST_CASE("diagnostics: the passes' warnings, as psysc check reports them") {
    std::string text = "object drag {\n    vel = vec3(0, 10, 0) + integrate(vec3(0, -9.8, 0) - 180 * vel);\n"
                       "    point(vel, white, 1);\n}\nspawn drag;\n";
    Analysis a = analyze("/tmp/w.psys", text);
    json d = diagnosticsByUri(a)["file:///tmp/w.psys"];
    REQUIRE(d.size() == 1);
    CHECK(d[0]["severity"] == 2);
    CHECK(d[0]["message"].get<std::string>().find("is stable only while") != std::string::npos);
    CHECK(d[0]["range"]["start"] == json{{"line", 1}, {"character", 27}});
}

TEST_CASE("a syntax error does not blank the file: hover, definition and symbols answer from the last text that parsed, away from the edit") {
    // The fireworks with an unfinished line after `vel`'s equation (line 5).
    std::string good = kFireworks;
    std::string broken = good;
    broken.insert(at(good, "    point(pos, white"), "    x = \n");
    Session s;
    s.request(1, "initialize", {{"initializationOptions", {{"debounceMs", 0}}}});
    std::string uri = "file:///tmp/fw.psys";
    auto open = [&](const std::string& text, int version) {
        s.server.handle({{"jsonrpc", "2.0"}, {"method", "textDocument/didOpen"},
                         {"params", {{"textDocument", {{"uri", uri}, {"version", version}, {"text", text}}}}}});
    };
    open(good, 1);
    s.out.clear();
    s.server.handle({{"jsonrpc", "2.0"}, {"method", "textDocument/didChange"},
                     {"params", {{"textDocument", {{"uri", uri}, {"version", 2}}}, {"contentChanges", {{{"text", broken}}}}}}});
    s.server.idle();
    s.server.settle();
    bool reported = false;  // the error is reported all the same
    for (const json& m : s.out)
        if (m.value("method", "") == "textDocument/publishDiagnostics" && m["params"]["version"] == 2)
            reported = !m["params"]["diagnostics"].empty();
    CHECK(reported);
    auto position = [&](const std::string& text, uint32_t offset) {
        SourceFile f("/tmp/fw.psys", text);
        return lsp::position(f, offset);
    };
    // Before the edit: `gravity` on line 4; after it, the spark's `rocket.vel`, shifted a line.
    json h = s.request(2, "textDocument/hover", {{"textDocument", {{"uri", uri}}}, {"position", position(broken, at(broken, "gravity", 2))}});
    CHECK(h["result"]["contents"]["value"].get<std::string>().find("fn gravity") != std::string::npos);
    json d = s.request(3, "textDocument/definition", {{"textDocument", {{"uri", uri}}}, {"position", position(broken, at(broken, "rocket.vel", 1, 8))}});
    CHECK(d["result"]["range"]["start"] == position(broken, at(broken, "vel =")));
    json symbols = s.request(4, "textDocument/documentSymbol", {{"textDocument", {{"uri", uri}}}});
    json rocket;
    for (const json& sym : symbols["result"])
        if (sym["name"] == "rocket") rocket = sym;
    REQUIRE(rocket.is_object());
    CHECK(rocket["range"]["end"]["line"] == 14);  // the object's `}`, a line down
    CHECK(rocket["children"].size() >= 4);        // its parameter and equations
    // On the unfinished line itself: nothing known.
    json none = s.request(5, "textDocument/hover", {{"textDocument", {{"uri", uri}}}, {"position", position(broken, at(broken, "x = ", 1, 1))}});
    CHECK_MESSAGE(none["result"].is_null(), none.dump());
}

TEST_CASE("edit map: offsets around one edit, both ways") {
    EditMap m("abcXYZdef", "abcQdef");
    CHECK(m.toOlder(2) == 2u);
    CHECK(m.toOlder(3) == 3u);
    CHECK(m.toOlder(4) == 6u);  // `d`, after the edit
    CHECK(m.toCurrent(6) == 4u);
    CHECK_FALSE(m.toCurrent(4).has_value());  // `Y`: replaced
    EditMap same("abc", "abc");
    CHECK(same.toCurrent(2) == 2u);
    CHECK(same.toOlder(3) == 3u);
}

namespace {

// The uses a references answer lists, as "line:character" in the named file.
std::vector<std::string> places(const json& locations, const std::string& uri) {
    std::vector<std::string> out;
    for (const json& l : locations)
        if (l["uri"] == uri)
            out.push_back(std::to_string(l["range"]["start"]["line"].get<int>()) + ":" +
                          std::to_string(l["range"]["start"]["character"].get<int>()));
    return out;
}

json at(Session& s, int id, const std::string& method, const std::string& uri, const std::string& text, uint32_t offset,
        json extra = json::object()) {
    SourceFile f("/x.psys", text);
    json params = {{"textDocument", {{"uri", uri}}}, {"position", lsp::position(f, offset)}};
    params.update(extra);
    return s.request(id, method, params);
}

}  // namespace

TEST_CASE("references: an equation read here, in a nested object's live read and in a swizzle's base, a function across an import") {
    TempDir dir;
    std::string lib = "fn wobble(x: float) -> float = sin(x * 3);\n";
    std::string main = "import \"lib.psys\";\n"
                       "object rocket {\n"
                       "    vel = vec3(0, wobble(age), 0);\n"
                       "    pos = integrate(vel);\n"
                       "    point(pos, white, vel.y);\n"
                       "    emit spark() count 1;\n"
                       "    object spark { point(rocket.vel, white, 1); }\n"
                       "}\nspawn rocket;\n";
    std::string libPath = dir.write("lib.psys", lib), mainPath = dir.write("main.psys", main);
    std::string libUri = uriFromPath(libPath), mainUri = uriFromPath(mainPath);
    Session s;
    s.request(1, "initialize");
    for (auto [uri, text] : {std::pair{libUri, lib}, std::pair{mainUri, main}})
        s.server.handle({{"jsonrpc", "2.0"}, {"method", "textDocument/didOpen"},
                         {"params", {{"textDocument", {{"uri", uri}, {"version", 1}, {"text", text}}}}}});
    json refs = at(s, 2, "textDocument/references", mainUri, main, at(main, "vel", 3, 1), {{"context", {{"includeDeclaration", true}}}});
    CHECK(places(refs["result"], mainUri) == std::vector<std::string>{"2:4", "3:20", "4:22", "6:32"});
    json noDecl = at(s, 3, "textDocument/references", mainUri, main, at(main, "vel", 1), {{"context", {{"includeDeclaration", false}}}});
    CHECK(places(noDecl["result"], mainUri) == std::vector<std::string>{"3:20", "4:22", "6:32"});
    // The library's function, asked for from the library's own document: its use in main too.
    json fromLib = at(s, 4, "textDocument/references", libUri, lib, at(lib, "wobble"));
    CHECK(places(fromLib["result"], libUri) == std::vector<std::string>{"0:3"});
    CHECK(places(fromLib["result"], mainUri) == std::vector<std::string>{"2:18"});
    // Highlight: this file's uses, the declaration as a write.
    json hl = at(s, 5, "textDocument/documentHighlight", mainUri, main, at(main, "pos", 2));
    REQUIRE(hl["result"].size() == 2);
    CHECK(hl["result"][0]["kind"] == 3);
    CHECK(hl["result"][1]["kind"] == 2);
    // Nothing to find on a built-in or a number.
    CHECK(at(s, 6, "textDocument/references", mainUri, main, at(main, "white"))["result"].is_null());
}

TEST_CASE("rename: every use across an import, and refused with the reason for a keyword, a built-in, a clash, the library") {
    TempDir dir;
    std::string lib = "const lift = 2;\n";
    std::string main = "import \"lib.psys\";\nimport \"std/shapes.psys\";\n"
                       "object o(h: float) {\n    y = lift * h;\n    z = y + 1;\n    point(vec3(0, y, z) + in_sphere(1), white, 1);\n}\n"
                       "spawn o(2);\n";
    std::string libPath = dir.write("lib.psys", lib), mainPath = dir.write("main.psys", main);
    std::string libUri = uriFromPath(libPath), mainUri = uriFromPath(mainPath);
    Session s;
    s.request(1, "initialize");
    s.server.handle({{"jsonrpc", "2.0"}, {"method", "textDocument/didOpen"},
                     {"params", {{"textDocument", {{"uri", mainUri}, {"version", 1}, {"text", main}}}}}});
    json r = at(s, 2, "textDocument/rename", mainUri, main, at(main, "lift"), {{"newName", "height"}});
    REQUIRE(r.contains("result"));
    CHECK(r["result"]["changes"][libUri].size() == 1);
    CHECK(r["result"]["changes"][mainUri].size() == 1);
    CHECK(r["result"]["changes"][mainUri][0]["newText"] == "height");
    json eq = at(s, 3, "textDocument/rename", mainUri, main, at(main, "y = "), {{"newName", "up"}});
    CHECK(eq["result"]["changes"][mainUri].size() == 3);  // its equation, `y + 1` and `vec3(0, y, z)`
    auto refused = [&](uint32_t offset, const std::string& name) {
        json e = at(s, 4, "textDocument/rename", mainUri, main, offset, {{"newName", name}});
        CHECK(e["error"]["code"] == error::kRequestFailed);
        return e["error"].value("message", std::string());
    };
    CHECK(refused(at(main, "y = "), "at").find("keyword") != std::string::npos);
    CHECK(refused(at(main, "y = "), "sin").find("built-in function") != std::string::npos);
    CHECK(refused(at(main, "y = "), "2y").find("not a name") != std::string::npos);
    CHECK(refused(at(main, "y = "), "z").find("already declared") != std::string::npos);
    CHECK(refused(at(main, "y = "), "h").find("already declared") != std::string::npos);
    CHECK(refused(at(main, "in_sphere"), "ball").find("standard library") != std::string::npos);
    CHECK(refused(at(main, "white"), "snow").find("no name to rename") != std::string::npos);
}

TEST_CASE("inlay hints: each equation's and let's type, and how each object that integrates is solved") {
    std::string text = "@integrator(rk4)\n"
                       "object rocket(ivel: vec3) {\n"
                       "    pos = origin + integrate(vel);\n"
                       "    vel = snapshot(ivel) + integrate(vec3(0, -9.8, 0));\n"
                       "    point(pos, white, 2);\n"
                       "}\n"
                       "@step(1/240)\n"
                       "object plain { c = 2; x = integrate(c); point(vec3(x), white, 1); }\n"
                       "object still { s = 1; point(vec3(s), white, 1); }\n"
                       "fn f(a: float) -> float {\n    let b = a * 2;\n    b\n}\n"
                       "spawn rocket(vec3(0, 5, 0));\nspawn plain;\nspawn still;\n";
    Analysis a = analyze("/tmp/hints.psys", text);
    REQUIRE(a.parsed);
    json hints = inlayHints(a, 0, static_cast<uint32_t>(text.size()));
    std::map<std::string, std::string> byPlace;  // "line:character" → label
    for (const json& h : hints)
        byPlace[std::to_string(h["position"]["line"].get<int>()) + ":" + std::to_string(h["position"]["character"].get<int>())] =
            h["label"].get<std::string>();
    CHECK(byPlace["2:7"] == ": vec3");                      // pos
    CHECK(byPlace["3:7"] == ": vec3");                      // vel
    CHECK(byPlace["1:13"] == "rk4, a step per update");     // rocket: its @integrator
    CHECK(byPlace["7:12"] == "semi_implicit, step 1/240 s");  // plain: the default method, its @step
    CHECK(byPlace["8:16"] == ": float");                    // still's s …
    CHECK(byPlace.count("8:12") == 0);                      // … and no method: it integrates nothing
    CHECK(byPlace["10:9"] == ": float");                    // let b
    // Only those in the range asked for.
    CHECK(inlayHints(a, at(text, "object plain"), at(text, "object still")).size() == 3);
}

TEST_CASE("completion: in a fn's body only what a fn may name, after a vector's name its components") {
    std::string text = "const k = 2;\nextern e: float = 1;\n"
                       "fn f(a: float) -> float = a + k;\n"
                       "object o(ivel: vec3) {\n    pos = vec3(1, 2, 3) + ivel;\n    c = pos.x;\n    point(pos, white, 1);\n}\n"
                       "spawn o(vec3(0));\n";
    Analysis a = analyze("/tmp/c.psys", text);
    REQUIRE(a.parsed);
    std::vector<std::string> inFn = labels(completion(a, text, at(text, "a + k", 1, 4)));
    for (const char* ok : {"a", "k", "sin", "rand", "pi"}) CHECK_MESSAGE(has(inFn, ok), ok);
    for (const char* bad : {"age", "dt", "time", "e", "o", "integrate", "snapshot", "prev"}) CHECK_MESSAGE(!has(inFn, bad), bad);
    // In an object, the same names are offered.
    std::vector<std::string> inObject = labels(completion(a, text, at(text, "pos.x", 1, 0)));
    for (const char* ok : {"age", "e", "integrate", "pos", "ivel"}) CHECK_MESSAGE(has(inObject, ok), ok);
    // After `pos.`: its components and swizzles.
    std::vector<std::string> members = labels(completion(a, text, at(text, "pos.x", 1, 4)));
    for (const char* ok : {"x", "y", "z", "r", "g", "b", "xyz"}) CHECK_MESSAGE(has(members, ok), ok);
    CHECK_FALSE(has(members, "w"));
}

TEST_CASE("folding ranges, workspace symbols across open documents, signature help for a call") {
    std::string text = "// A rocket.\n// Two lines of comment.\nfn lift(m: float, k: vec3) -> vec3 = k * m;\n"
                       "/* a block\n   comment */\n"
                       "object rocket {\n    vel = lift(2, vec3(0, clamp(age, 0, 1), 0));\n"
                       "    point(vel, white, 1);\n}\nspawn rocket;\n";
    Analysis a = analyze("/tmp/o.psys", text);
    REQUIRE(a.parsed);
    json folds = foldingRanges(a);
    auto folded = [&](int first, int last, const char* kind) {
        for (const json& f : folds)
            if (f["startLine"] == first && f["endLine"] == last && f["kind"] == kind) return true;
        return false;
    };
    CHECK(folded(0, 1, "comment"));  // two `//` lines
    CHECK(folded(3, 4, "comment"));  // the block comment
    CHECK(folded(5, 8, "region"));   // the object
    CHECK(folds.size() == 3);         // (the one-line fn does not fold)

    std::string other = "object puff { point(vec3(0), white, 1); }\nspawn puff;\n";
    Analysis b = analyze("/tmp/p.psys", other);
    REQUIRE(b.parsed);
    json symbols = workspaceSymbols({&a, &b}, "rk");  // r…k: rocket, and not puff
    REQUIRE(symbols.size() == 1);
    CHECK(symbols[0]["name"] == "rocket");
    CHECK(workspaceSymbols({&a, &b}, "").size() == 4);  // lift, rocket, vel, puff
    json vel = workspaceSymbols({&a, &b}, "vel");
    REQUIRE(vel.size() == 1);
    CHECK(vel[0]["containerName"] == "rocket");

    // In `lift(2, vec3(…))` at the second argument; inside clamp's first.
    json help = signatureHelp(a, text, at(text, "vec3(0, clamp"));
    CHECK(help["signatures"][0]["label"].get<std::string>().starts_with("fn lift(m: float, k: vec3)"));
    CHECK(help["activeParameter"] == 1);
    json p = help["signatures"][0]["parameters"][1]["label"];
    CHECK(help["signatures"][0]["label"].get<std::string>().substr(p[0].get<size_t>(), p[1].get<size_t>() - p[0].get<size_t>()) == "k: vec3");
    json inner = signatureHelp(a, text, at(text, "age, 0, 1", 1, 3));
    CHECK(inner["signatures"][0]["label"].get<std::string>().starts_with("clamp("));
    CHECK(inner["activeParameter"] == 0);
    CHECK(signatureHelp(a, text, at(text, "spawn")).is_null());
}
