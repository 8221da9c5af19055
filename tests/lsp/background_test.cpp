// Analyses after an edit run in the background: the server answers the other documents,
// completion and signature help meanwhile, and an analysis of a text edited since is never
// published.
#include <doctest/doctest.h>

#include <thread>

#include "lsp/positions.h"
#include "lsp_support.h"

using namespace psys;
using namespace psys::lsp;
using namespace psys::lsp::test;
using nlohmann::json;

namespace {

// `n` objects: an analysis of a few hundred milliseconds.
std::string many(int n, const std::string& tag) {
    std::string text;
    for (int i = 0; i < n; ++i)
        text += "object o" + std::to_string(i) + " {\n    pos = origin + vec3(" + std::to_string(i) + ", 0, 0);\n" +
                "    point(pos, " + tag + ", 1);\n    kill when age > 1;\n}\n";
    return text;
}

json message(const std::string& method, json params) {
    return {{"jsonrpc", "2.0"}, {"method", method}, {"params", std::move(params)}};
}

}  // namespace

TEST_CASE("background analysis: requests are answered while it runs, and a stale one is never published") {
    std::vector<json> out;
    ServerOptions options;
    options.debounce = std::chrono::milliseconds(0);
    Server server(exactReads(options), [&](const json& m) { out.push_back(m); });
    server.handle({{"jsonrpc", "2.0"}, {"id", 1}, {"method", "initialize"}, {"params", json::object()}});
    std::string small = kFireworks;
    server.handle(message("textDocument/didOpen", {{"textDocument", {{"uri", "file:///tmp/small.psys"}, {"version", 1},
                                                                     {"text", small}}}}));
    server.handle(message("textDocument/didOpen", {{"textDocument", {{"uri", "file:///tmp/big.psys"}, {"version", 1},
                                                                     {"text", many(3000, "white")}}}}));
    auto publishedFor = [&](int version) {
        int n = 0;
        for (const json& m : out)
            n += m.value("method", "") == "textDocument/publishDiagnostics" && m["params"]["uri"] == "file:///tmp/big.psys" &&
                 m["params"]["version"] == version;
        return n;
    };
    auto change = [&](int version, const std::string& text) {
        server.handle(message("textDocument/didChange", {{"textDocument", {{"uri", "file:///tmp/big.psys"}, {"version", version}}},
                                                         {"contentChanges", {{{"text", text}}}}}));
    };
    out.clear();
    change(2, many(3000, "red"));
    server.idle();
    REQUIRE(server.busy());
    // Another document's hover, and the big one's completion: answered, nothing waited for.
    server.handle({{"jsonrpc", "2.0"}, {"id", 2}, {"method", "textDocument/hover"},
                   {"params", {{"textDocument", {{"uri", "file:///tmp/small.psys"}}}, {"position", {{"line", 1}, {"character", 4}}}}}});
    server.handle({{"jsonrpc", "2.0"}, {"id", 3}, {"method", "textDocument/completion"},
                   {"params", {{"textDocument", {{"uri", "file:///tmp/big.psys"}}}, {"position", {{"line", 2}, {"character", 10}}}}}});
    REQUIRE(out.size() == 2);
    CHECK(out[0]["id"] == 2);
    CHECK(out[0]["result"]["contents"]["value"].get<std::string>().find("fn gravity") != std::string::npos);
    CHECK(out[1]["id"] == 3);
    CHECK(out[1]["result"]["items"].size() > 10);
    CHECK(server.busy());
    // An edit while it runs: version 2 is cancelled and never published; version 3 is.
    change(3, many(3000, "green"));
    for (int i = 0; i < 100000 && (server.busy() || server.nextDeadline()); ++i) {
        server.idle();
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    CHECK_FALSE(server.busy());
    CHECK(publishedFor(2) == 0);
    CHECK(publishedFor(3) == 1);
    // A request about the document analysed in the background gets the analysis of its text.
    json hover = [&] {
        out.clear();
        server.handle({{"jsonrpc", "2.0"}, {"id", 4}, {"method", "textDocument/hover"},
                       {"params", {{"textDocument", {{"uri", "file:///tmp/big.psys"}}}, {"position", {{"line", 2}, {"character", 16}}}}}});
        return out.back();
    }();
    CHECK(hover["result"]["contents"]["value"].get<std::string>().find("green") != std::string::npos);
}

TEST_CASE("an open, unsaved file is what its importers read: an edit to it checks them again, and definitions point into its text") {
    // main.psys imports lib.psys and calls `lift`; lib renames it to `rise` without saving.
    TempDir dir;
    std::string lib = "fn lift(h: float) -> vec3 = vec3(0, h, 0);\n";
    std::string main = "import \"lib.psys\";\nobject o {\n    pos = origin + lift(2);\n    point(pos, white, 1);\n"
                       "    kill when age > 1;\n}\nspawn o;\n";
    std::string libPath = dir.write("lib.psys", lib), mainPath = dir.write("main.psys", main);
    std::string libUri = uriFromPath(libPath), mainUri = uriFromPath(mainPath);
    std::vector<json> out;
    ServerOptions options;
    options.debounce = std::chrono::milliseconds(0);
    Server server(exactReads(options), [&](const json& m) { out.push_back(m); });
    server.handle({{"jsonrpc", "2.0"}, {"id", 1}, {"method", "initialize"}, {"params", json::object()}});
    auto open = [&](const std::string& uri, const std::string& text) {
        server.handle(message("textDocument/didOpen", {{"textDocument", {{"uri", uri}, {"version", 1}, {"text", text}}}}));
    };
    auto change = [&](const std::string& uri, int version, const std::string& text) {
        server.handle(message("textDocument/didChange", {{"textDocument", {{"uri", uri}, {"version", version}}},
                                                         {"contentChanges", {{{"text", text}}}}}));
    };
    auto settle = [&] {
        for (int i = 0; i < 100000 && (server.busy() || server.nextDeadline()); ++i) {
            server.idle();
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
    };
    // The diagnostics last published for main.psys.
    auto mainErrors = [&] {
        std::vector<std::string> messages;
        bool seen = false;
        for (const json& m : out)
            if (m.value("method", "") == "textDocument/publishDiagnostics" && m["params"]["uri"] == mainUri) {
                seen = true;
                messages.clear();
                for (const json& d : m["params"]["diagnostics"]) messages.push_back(d["message"]);
            }
        REQUIRE(seen);
        return messages;
    };
    open(mainUri, main);
    open(libUri, lib);
    settle();
    CHECK(mainErrors().empty());

    // lib renames `lift` (unsaved): main is checked again, against lib's text in the editor.
    out.clear();
    std::string renamed = "fn rise(h: float) -> vec3 = vec3(0, h, 0);\n";
    change(libUri, 2, renamed);
    settle();
    auto errors = mainErrors();
    REQUIRE(errors.size() == 1);
    CHECK(errors[0].find("unknown function `lift`") != std::string::npos);

    // main follows (as a rename across both buffers does): clean, and `rise` is defined in
    // lib's unsaved text.
    out.clear();
    std::string follows = main;
    follows.replace(follows.find("lift"), 4, "rise");
    change(mainUri, 2, follows);
    settle();
    CHECK(mainErrors().empty());
    SourceFile now(mainPath, follows);
    json definition = [&] {
        out.clear();
        server.handle({{"jsonrpc", "2.0"}, {"id", 5}, {"method", "textDocument/definition"},
                       {"params", {{"textDocument", {{"uri", mainUri}}}, {"position", position(now, at(follows, "rise", 1, 1))}}}});
        return out.back();
    }();
    REQUIRE(definition["result"].is_object());
    CHECK(definition["result"]["uri"] == libUri);
    CHECK(definition["result"]["range"]["start"] == json({{"line", 0}, {"character", 3}}));

    // lib closed unsaved: the disk's `lift` is what main reads again.
    out.clear();
    server.handle(message("textDocument/didClose", {{"textDocument", {{"uri", libUri}}}}));
    settle();
    errors = mainErrors();
    REQUIRE(errors.size() == 1);
    CHECK(errors[0].find("unknown function `rise`") != std::string::npos);
}

TEST_CASE("reads never wait on a slow analysis: they answer from the last one, moved through the edits since") {
    SlowSession session;  // every analysis slow: reads answer from the last one
    auto& server = session.server;
    auto& out = session.out;
    auto request = [&](int id, const std::string& method, json params) { return session.request(id, method, std::move(params)); };
    request(1, "initialize", json::object());
    std::string uri = "file:///tmp/never_waits.psys", text = kFireworks;
    server.handle({{"jsonrpc", "2.0"}, {"method", "textDocument/didOpen"},
                   {"params", {{"textDocument", {{"uri", uri}, {"version", 1}, {"text", text}}}}}});
    // Two lines above everything, one of them a new constant: not analysed yet (debounce).
    std::string edited = "const lift = 2;\n\n" + text;
    server.handle({{"jsonrpc", "2.0"}, {"method", "textDocument/didChange"},
                   {"params", {{"textDocument", {{"uri", uri}, {"version", 2}}}, {"contentChanges", {{{"text", edited}}}}}}});
    auto pos = [&](uint32_t offset) { return position(SourceFile("x", edited), offset); };
    json doc = {{"uri", uri}};
    json h = request(2, "textDocument/hover", {{"textDocument", doc}, {"position", pos(at(edited, "gravity(0.3)", 1, 2))}});
    REQUIRE(h.is_object());
    CHECK(h["contents"]["value"].get<std::string>().find("fn gravity") != std::string::npos);
    CHECK(h["range"]["start"]["line"] == 6);  // where the call is now
    json d = request(3, "textDocument/definition", {{"textDocument", doc}, {"position", pos(at(edited, "gravity(0.3)", 1, 2))}});
    CHECK(d["range"]["start"] == json{{"line", 3}, {"character", 3}});
    CHECK(request(4, "textDocument/hover", {{"textDocument", doc}, {"position", pos(7)}}).is_null());  // `lift`: not known yet
    json symbols = request(5, "textDocument/documentSymbol", {{"textDocument", doc}});
    bool rocketMoved = false;
    for (const json& sym : symbols) rocketMoved |= sym["name"] == "rocket" && sym["range"]["start"]["line"] == 4;
    CHECK(rocketMoved);
    for (const json& m : out) CHECK(m.value("method", "") != "textDocument/publishDiagnostics");  // nothing analysed
    // Once the new analysis is in, the new constant is known.
    CHECK(server.nextDeadline().has_value());
    request(6, "textDocument/references", {{"textDocument", doc}, {"position", pos(7)}});  // (waits: analyses)
    json fresh = request(7, "textDocument/hover", {{"textDocument", doc}, {"position", pos(7)}});
    REQUIRE(fresh.is_object());
    CHECK(fresh["contents"]["value"].get<std::string>().find("const lift") != std::string::npos);
}

namespace {

// A server whose every analysis's passes count as slow, with one document open (an
// object whose decay is too fast for its integrator: the passes warn).
struct SlowPasses {
    std::vector<json> out;
    Server server;
    std::string uri = "file:///tmp/passes.psys";
    std::string text = "object drag {\n    vel = vec3(0, 10, 0) + integrate(vec3(0, -9.8, 0) - 180 * vel);\n"
                       "    point(vel, white, 1);\n}\nspawn drag;\n";
    static ServerOptions options(std::chrono::milliseconds debounce) {
        ServerOptions o;
        o.debounce = debounce;
        o.quickAnalysisMs = 0;
        return o;
    }
    // (The document is analysed as it opens, the passes in that analysis.)
    explicit SlowPasses(std::chrono::milliseconds debounce = std::chrono::milliseconds(0))
        : server(options(debounce), [this](const json& m) { out.push_back(m); }) {
        server.handle({{"jsonrpc", "2.0"}, {"id", 1}, {"method", "initialize"}, {"params", json::object()}});
        server.handle(message("textDocument/didOpen", {{"textDocument", {{"uri", uri}, {"version", 1}, {"text", text}}}}));
    }
    // Runs the server's loop until nothing is left to do; how many turns it took.
    int settle() {
        int rounds = 0;
        for (; rounds < 5000 && (server.busy() || server.nextDeadline()); ++rounds) {
            server.idle();
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
        return rounds;
    }
    void change(int version, const std::string& with) {
        server.handle(message("textDocument/didChange", {{"textDocument", {{"uri", uri}, {"version", version}}},
                                                         {"contentChanges", {{{"text", with}}}}}));
    }
};

}  // namespace

TEST_CASE("slow passes: an edit publishes the front end's diagnostics first, with the passes' last warnings moved, then the passes'") {
    SlowPasses s;
    std::vector<json>& out = s.out;
    const std::string &uri = s.uri, &text = s.text;
    // Each publication for `uri`: (version, the lines of its warnings, whether it has an error).
    struct Published {
        int version;
        std::vector<int> warnings;
        bool error;
    };
    auto published = [&] {
        std::vector<Published> list;
        for (const json& m : out) {
            if (m.value("method", "") != "textDocument/publishDiagnostics" || m["params"]["uri"] != uri) continue;
            Published p{m["params"]["version"].get<int>(), {}, false};
            for (const json& d : m["params"]["diagnostics"]) {
                if (d["severity"] == 1) p.error = true;
                if (d["severity"] == 2 && d["message"].get<std::string>().find("decays") != std::string::npos)
                    p.warnings.push_back(d["range"]["start"]["line"].get<int>());
            }
            list.push_back(p);
        }
        return list;
    };
    auto settle = [&] { s.settle(); };
    auto change = [&](int version, const std::string& with) { s.change(version, with); };
    settle();
    auto first = published();
    REQUIRE(first.size() == 1);  // the first analysis runs the passes in it
    CHECK(first[0].warnings == std::vector<int>{1});

    // A line above: the warning is carried a line down at once, then the passes say it again.
    out.clear();
    change(2, "// drag\n" + text);
    settle();
    auto moved = published();
    REQUIRE(moved.size() == 2);
    CHECK(moved[0].version == 2);
    CHECK(moved[0].warnings == std::vector<int>{2});
    CHECK(moved[1].version == 2);
    CHECK(moved[1].warnings == std::vector<int>{2});

    // An edit inside the warned equation: not carried (what it warned of may be gone); the
    // passes find the decay still too fast.
    out.clear();
    std::string faster = "// drag\n" + text;
    faster.replace(faster.find("180"), 3, "190");
    change(3, faster);
    settle();
    auto touched = published();
    REQUIRE(touched.size() == 2);
    CHECK(touched[0].warnings.empty());
    CHECK(touched[1].warnings == std::vector<int>{2});

    // A type error: no passes to run, nothing carried, one publication.
    out.clear();
    std::string wrong = faster;
    wrong.replace(wrong.find("point(vel"), 9, "point(true");
    change(4, wrong);
    settle();
    auto broken = published();
    REQUIRE(broken.size() == 1);
    CHECK(broken[0].error);
    CHECK(broken[0].warnings.empty());
}

TEST_CASE("slow passes: an error typed before they run leaves nothing due (no analysis after analysis)") {
    SlowPasses s;
    std::vector<json>& out = s.out;
    const std::string& text = s.text;
    Server& server = s.server;
    auto settle = [&] { return s.settle(); };
    auto change = [&](int version, const std::string& with) { s.change(version, with); };
    settle();
    // A clean edit: its front end published, its passes due; then, before they run, a type
    // error and a syntax error, each analysed on its own.
    for (const std::string& broken : {std::string("point(true"), std::string("point(vel, white, 1")}) {
        out.clear();
        change(2, "// x\n" + text);
        for (int i = 0; i < 5000 && out.empty(); ++i) {
            server.idle();
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
        REQUIRE_FALSE(out.empty());
        std::string wrong = text;
        wrong.replace(wrong.find("point(vel"), 9, broken);
        change(3, wrong);
        CHECK(settle() < 5000);
        CHECK_FALSE(server.busy());
        int published = 0;
        for (const json& m : out) published += m.value("method", "") == "textDocument/publishDiagnostics" && m["params"]["version"] == 3;
        CHECK(published == 1);
    }
}

TEST_CASE("slow passes: a request that waits for the edited text's analysis does not wait for the passes") {
    SlowPasses s(std::chrono::milliseconds(60000));  // edits wait: the request analyses
    CHECK_FALSE(s.server.busy());
    s.change(2, "// x\n" + s.text);
    s.out.clear();
    s.server.handle({{"jsonrpc", "2.0"}, {"id", 2}, {"method", "textDocument/references"},
                     {"params", {{"textDocument", {{"uri", s.uri}}}, {"position", {{"line", 2}, {"character", 5}}},
                                 {"context", {{"includeDeclaration", true}}}}}});
    // Answered after the front end alone (its diagnostics out, the warning carried a line
    // down); the passes are left to run in the background.
    bool warned = false;
    for (const json& m : s.out)
        if (m.value("method", "") == "textDocument/publishDiagnostics")
            for (const json& d : m["params"]["diagnostics"]) warned |= d["range"]["start"]["line"] == 2;
    CHECK(warned);
    CHECK(s.server.busy());
}
