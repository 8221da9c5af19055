// The requests beyond the first round's: prepareRename, declaration, document links,
// selection ranges, semantic tokens for a range and as a delta, pull diagnostics,
// completionItem/resolve, range formatting, signature help for commands and `emit T(`,
// hover on types, commands and `@shape`'s names; and what a file with syntax errors still
// answers (two edits apart since the last text that parsed; opened broken).
#include <doctest/doctest.h>

#include <fstream>
#include <set>
#include <sstream>

#include "lsp/positions.h"
#include "lsp/recover.h"
#include "lsp/salvage.h"
#include "lsp/transport.h"
#include "lsp_support.h"

using namespace psys;
using namespace psys::lsp;
using namespace psys::lsp::test;
using nlohmann::json;

namespace {

std::string readSample(const std::string& name) {
    std::ifstream in(std::string(PSYS_SAMPLES_DIR) + "/" + name);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

// A session with one document open (debounce 0, so an edit is analysed on the next request).
struct Open : Session {
    std::string uri;
    int version = 1;
    Open(const std::string& text, std::string u = "file:///tmp/requests.psys") : uri(std::move(u)) {
        request(1, "initialize", {{"initializationOptions", {{"debounceMs", 0}}}});
        server.handle({{"jsonrpc", "2.0"}, {"method", "textDocument/didOpen"},
                       {"params", {{"textDocument", {{"uri", uri}, {"version", version}, {"text", text}}}}}});
    }
    void change(const std::string& text) {
        server.handle({{"jsonrpc", "2.0"}, {"method", "textDocument/didChange"},
                       {"params", {{"textDocument", {{"uri", uri}, {"version", ++version}}}, {"contentChanges", {{{"text", text}}}}}}});
    }
    json doc() const { return {{"uri", uri}}; }
    json ask(const std::string& method, json params) {
        params["textDocument"] = doc();
        return request(++id, method, std::move(params));
    }
    json at(const std::string& method, const std::string& text, uint32_t offset, json extra = json::object()) {
        extra["position"] = position(SourceFile("x", text), offset);
        return ask(method, std::move(extra));
    }
    int id = 100;
};

std::string hoverOf(const json& answer) {
    return answer["result"].is_null() ? std::string() : answer["result"]["contents"]["value"].get<std::string>();
}

std::string replaceLine(std::string text, int line, const std::string& with) {
    size_t b = 0;
    for (int i = 0; i < line; ++i) b = text.find('\n', b) + 1;
    size_t e = text.find('\n', b);
    return text.replace(b, e - b, with);
}

}  // namespace

TEST_CASE("capabilities: the server announces every request it answers") {
    Session s;
    json caps = s.request(1, "initialize")["result"]["capabilities"];
    CHECK(caps["renameProvider"]["prepareProvider"] == true);
    for (const char* p : {"declarationProvider", "selectionRangeProvider", "documentRangeFormattingProvider"})
        CHECK_MESSAGE(caps[p] == true, p);
    CHECK(caps["documentLinkProvider"].is_object());
    CHECK_FALSE(caps.contains("diagnosticProvider"));  // (the client did not say it pulls)
    CHECK(caps["completionProvider"]["resolveProvider"] == true);
}

TEST_CASE("a client that pulls diagnostics gets a document's own only when it asks, not pushed as well") {
    Session s;
    json caps = s.request(1, "initialize", {{"capabilities", {{"textDocument", {{"diagnostic", json::object()}}}}}})["result"]["capabilities"];
    CHECK(caps["diagnosticProvider"]["interFileDependencies"] == true);
    std::string uri = "file:///tmp/pulled.psys";
    s.out.clear();
    s.server.handle({{"jsonrpc", "2.0"}, {"method", "textDocument/didOpen"},
                     {"params", {{"textDocument", {{"uri", uri}, {"version", 1}, {"text", "const a = nope;\n"}}}}}});
    for (const json& m : s.out) CHECK(m.value("method", "") != "textDocument/publishDiagnostics");
    json report = s.request(2, "textDocument/diagnostic", {{"textDocument", {{"uri", uri}}}})["result"];
    CHECK(report["items"].size() == 1);
}

TEST_CASE("prepareRename: the name's range and text, or why it cannot be renamed, and declaration is the definition") {
    std::string text = kFireworks;
    Open s(text);
    json r = s.at("textDocument/prepareRename", text, at(text, "vel.y", 1, 1));
    CHECK(r["result"]["placeholder"] == "vel");
    CHECK(r["result"]["range"] == range(SourceFile("x", text), at(text, "vel.y"), at(text, "vel.y") + 3));
    json refused = s.at("textDocument/prepareRename", text, at(text, "integrate", 1, 2));
    CHECK(refused["error"]["code"] == error::kRequestFailed);
    CHECK(refused["error"]["message"].get<std::string>().find("built-in") != std::string::npos);
    json declaration = s.at("textDocument/declaration", text, at(text, "gravity(0.3)"));
    json definition = s.at("textDocument/definition", text, at(text, "gravity(0.3)"));
    CHECK(declaration["result"] == definition["result"]);
    CHECK(declaration["result"]["range"]["start"]["line"] == 1);
}

TEST_CASE("document links: an import's path links to the file it loads, a std/ import to the library's") {
    TempDir dir;
    dir.write("lib.psys", "fn lift(x: float) -> float = x * 2;\n");
    std::string text = "import \"lib.psys\";\nimport \"std/forces.psys\";\nconst k = lift(1);\n";
    std::string main = dir.write("main.psys", text);
    Open s(text, uriFromPath(main));
    json answer = s.ask("textDocument/documentLink", json::object());
    json links = answer["result"];
    INFO(answer.dump());
    REQUIRE(links.size() == 2);
    CHECK(links[0]["target"] == uriFromPath((dir.path / "lib.psys").string()));
    CHECK(links[0]["range"]["start"] == json{{"line", 0}, {"character", 7}});
    CHECK(links[1]["target"].get<std::string>().find("std/forces.psys") != std::string::npos);
}

TEST_CASE("selection ranges grow from the name through its expression and declaration to the file") {
    std::string text = kFireworks;
    Open s(text);
    uint32_t cursor = at(text, "gravity(0.3)", 1, 2);
    json r = s.ask("textDocument/selectionRange", {{"positions", {position(SourceFile("x", text), cursor)}}});
    REQUIRE(r["result"].size() == 1);
    SourceFile f("x", text);
    std::vector<std::pair<uint32_t, uint32_t>> chain;
    for (const json* x = &r["result"][0]; x; x = x->contains("parent") ? &(*x)["parent"] : nullptr)
        chain.push_back({offsetOf(f, (*x)["range"]["start"]), offsetOf(f, (*x)["range"]["end"])});
    REQUIRE(chain.size() >= 4);
    CHECK(text.substr(chain[0].first, chain[0].second - chain[0].first) == "gravity");
    for (size_t i = 1; i < chain.size(); ++i) {
        CHECK(chain[i].first <= chain[i - 1].first);
        CHECK(chain[i - 1].second <= chain[i].second);
        CHECK(chain[i] != chain[i - 1]);
    }
    CHECK(chain.back() == std::pair<uint32_t, uint32_t>{0, static_cast<uint32_t>(text.size())});
    bool rocket = false;  // the object's declaration is one of the steps
    for (auto [b, e] : chain) rocket |= text.compare(b, 14, "object rocket(") == 0;
    CHECK(rocket);
}

TEST_CASE("semantic tokens: for a range, and as a delta from the last answer that rebuilds the full list") {
    std::string text = kFireworks;
    Open s(text);
    json full = s.ask("textDocument/semanticTokens/full", json::object())["result"];
    REQUIRE(full.contains("resultId"));
    // A range: only the tokens of lines 2–3 (rocket's first lines), the first one relative to the file's start.
    json part = s.ask("textDocument/semanticTokens/range",
                      {{"range", {{"start", {{"line", 2}, {"character", 0}}}, {"end", {{"line", 4}, {"character", 0}}}}}})["result"];
    REQUIRE(part["data"].size() % 5 == 0);
    CHECK(part["data"].size() > 0);
    CHECK(part["data"].size() < full["data"].size());
    CHECK(part["data"][0] == 2);
    // An edit inside rocket, then a delta: its edits applied to the last list give the new full list.
    std::string edited = text;
    edited.insert(at(text, "    point(pos, white"), "    glow = vel * 2;\n");
    s.change(edited);
    json delta = s.ask("textDocument/semanticTokens/full/delta", {{"previousResultId", full["resultId"]}})["result"];
    REQUIRE(delta.contains("edits"));
    std::vector<json> data(full["data"].begin(), full["data"].end());
    for (const json& e : delta["edits"]) {
        size_t start = e["start"], count = e["deleteCount"];
        data.erase(data.begin() + static_cast<long>(start), data.begin() + static_cast<long>(start + count));
        data.insert(data.begin() + static_cast<long>(start), e["data"].begin(), e["data"].end());
    }
    json now = semanticTokens(analyze("/tmp/requests.psys", edited))["data"];
    CHECK(json(data) == now);
    CHECK(delta["edits"][0]["data"].size() < now.size() / 2);  // not the whole list again
    // An unknown previous id: the full list.
    json fresh = s.ask("textDocument/semanticTokens/full/delta", {{"previousResultId", "nope"}})["result"];
    CHECK(fresh["data"] == now);
}

TEST_CASE("pull diagnostics: the document's report, the same diagnostics as published") {
    std::string text = "object o { pos = vec3(0) + nope; point(pos, white, 1); }\nspawn o;\n";
    Open s(text);
    json report = s.ask("textDocument/diagnostic", json::object())["result"];
    CHECK(report["kind"] == "full");
    REQUIRE(report["items"].size() == 1);
    CHECK(report["items"][0]["message"].get<std::string>().find("nope") != std::string::npos);
}

TEST_CASE("completionItem/resolve adds what a built-in word is, and hover explains types, commands and @shape's names") {
    Session s;
    s.request(1, "initialize");
    json sprite = s.request(2, "completionItem/resolve", {{"label", "sprite"}, {"kind", 14}})["result"];
    CHECK(sprite["documentation"]["value"].get<std::string>().find("camera-facing") != std::string::npos);
    json mine = s.request(3, "completionItem/resolve", {{"label", "spark"}, {"kind", 7}, {"detail", "object spark"}})["result"];
    CHECK(mine == json{{"label", "spark"}, {"kind", 7}, {"detail", "object spark"}});  // complete as listed
    std::string text = readSample("fireworks.psys");
    Analysis a = analyze("/tmp/fireworks.psys", text);
    CHECK(hoverText(a, at(text, "vec3, ivel", 1, 1)).find("three floats") != std::string::npos);
    CHECK(hoverText(a, at(text, "@shape(star)", 1, 8)).find("four-pointed") != std::string::npos);
    CHECK(hoverText(a, at(text, "kill when", 1, 1)).find("dies") != std::string::npos);
    std::string spriteHover = hoverText(a, at(text, "sprite(pos", 1, 2));
    CHECK(spriteHover.find("sprite(position: vec3, colour: vec4, size: float, rotation: float, frame: float)") !=
          std::string::npos);
    CHECK(hoverText(a, at(text, "emit spark", 1, 1)).find("creates objects") != std::string::npos);
}

TEST_CASE("signature help for drawing commands and for the arguments of emit T(") {
    std::string text = kFireworks;
    Analysis a = analyze("/tmp/fw.psys", text);
    json point = signatureHelp(a, text, at(text, "white, 2", 1, 7));
    REQUIRE(point.is_object());
    CHECK(point["signatures"][0]["label"] == "point(position: vec3, colour: vec4, size: float)");
    CHECK(point["activeParameter"] == 2);
    json emit = signatureHelp(a, text, at(text, "spark(pos)", 1, 6));
    REQUIRE(emit.is_object());
    CHECK(emit["signatures"][0]["label"] == "object spark(ipos: vec3)");
    CHECK(emit["activeParameter"] == 0);
    json spawn = signatureHelp(a, text, at(text, "rocket(vec3", 1, 7));
    REQUIRE(spawn.is_object());
    CHECK(spawn["signatures"][0]["label"] == "object rocket(ivel: vec3)");
}

TEST_CASE("range formatting changes only the lines asked for") {
    std::string text = "const a=1;\nobject o {\npos=vec3(a);\n  point(pos,white,1);\n}\nconst b  =  2;\nspawn o;\n";
    Open s(text);
    json r = s.ask("textDocument/rangeFormatting",
                   {{"range", {{"start", {{"line", 1}, {"character", 0}}}, {"end", {{"line", 4}, {"character", 1}}}}},
                    {"options", {{"tabSize", 4}, {"insertSpaces", true}}}});
    json edits = r["result"];
    REQUIRE(edits.size() > 0);
    std::string out = text;
    SourceFile f("x", text);
    for (auto it = edits.rbegin(); it != edits.rend(); ++it) {  // (edits are in order: apply from the end)
        uint32_t b = offsetOf(f, (*it)["range"]["start"]), e = offsetOf(f, (*it)["range"]["end"]);
        out = out.substr(0, b) + (*it)["newText"].get<std::string>() + out.substr(e);
    }
    CHECK(out == "const a=1;\nobject o {\n    pos = vec3(a);\n    point(pos, white, 1);\n}\nconst b  =  2;\nspawn o;\n");
    json broken = s.ask("textDocument/rangeFormatting", {{"range", {{"start", {{"line", 0}, {"character", 0}}}, {"end", {{"line", 0}, {"character", 1}}}}}});
    CHECK(broken["result"].is_array());
}

TEST_CASE("edit map: two edits apart keep what lies between them where it was") {
    std::string older = "one\ntwo\nthree\nfour\nfive\n", current = "one\nTWO\nthree\nfour\nfive!\n";
    EditMap m(older, current);
    CHECK(m.edits() == 2);
    CHECK(m.toCurrent(static_cast<uint32_t>(older.find("three"))) == current.find("three"));
    CHECK(m.toCurrent(static_cast<uint32_t>(older.find("four")) + 2) == current.find("four") + 2);
    CHECK_FALSE(m.toCurrent(static_cast<uint32_t>(older.find("two")) + 1).has_value());
    // An insertion: a range that starts where text was inserted starts after it.
    EditMap insert("ab\ncd\n", "ab\nXYcd\n");
    CHECK(insert.toCurrent(3) == 3u);
    CHECK(insert.toCurrent(3, true) == 5u);
}

TEST_CASE("a syntax error two edits away from the last text that parsed: hover answers between them") {
    // fireworks; line 31 changed (and parses); then put back, and line 43 left unfinished.
    std::string text = readSample("fireworks.psys");
    REQUIRE(text.find("@shape(star)") != std::string::npos);
    Open s(text);
    std::string changed = replaceLine(text, 30, "@integrator(rk4)");
    s.change(changed);
    CHECK(s.ask("textDocument/documentSymbol", json::object())["result"].size() > 3);  // (analysed: it parses)
    std::string broken = replaceLine(text, 42, "    tint = snapshot(vec4(0.35 + ");
    s.change(broken);
    json gravity = s.at("textDocument/hover", broken, offsetOf(SourceFile("x", broken), json{{"line", 41}, {"character", 38}}));
    CHECK(hoverText(analyze("/tmp/x.psys", text), offsetOf(SourceFile("x", text), json{{"line", 41}, {"character", 38}})) ==
          hoverOf(gravity));
    CHECK(hoverOf(gravity).find("fn gravity") != std::string::npos);
    json pos = s.at("textDocument/hover", broken, offsetOf(SourceFile("x", broken), json{{"line", 40}, {"character", 5}}));
    CHECK(hoverOf(pos).find("pos: vec3") != std::string::npos);
}

TEST_CASE("a file opened with a syntax error: outline, hover and definition everywhere but its broken declaration") {
    std::string text = readSample("fireworks.psys");
    std::string broken = replaceLine(text, 42, "    tint = snapshot(vec4(0.35 + ");  // inside rocket
    Open s(broken);
    bool reported = false;
    for (const json& m : s.out)
        if (m.value("method", "") == "textDocument/publishDiagnostics") reported |= !m["params"]["diagnostics"].empty();
    json symbols = s.ask("textDocument/documentSymbol", json::object())["result"];
    std::vector<std::string> names;
    for (const json& sym : symbols) names.push_back(sym["name"]);
    CHECK(has(names, "star"));
    CHECK(has(names, "gravity"));
    CHECK_FALSE(has(names, "rocket"));  // the broken declaration
    // Hover in star (line 35: `vel = snapshot(ivel) + integrate(gravity(0.5) …`) and definition from it.
    uint32_t g = at(broken, "gravity(0.5)", 1, 2);
    CHECK(hoverOf(s.at("textDocument/hover", broken, g)).find("fn gravity") != std::string::npos);
    CHECK(s.at("textDocument/definition", broken, g)["result"]["range"]["start"]["line"].is_number());
    CHECK(hoverOf(s.at("textDocument/hover", broken, at(broken, "gravity(0.3)", 1, 2))).empty());  // in rocket
    // The diagnostics are the text's own: the syntax error, not the blanked text's.
    json report = s.ask("textDocument/diagnostic", json::object())["result"];
    REQUIRE(report["items"].size() >= 1);
    CHECK(report["items"][0]["range"]["start"]["line"].get<int>() >= 42);
    (void)reported;
}

TEST_CASE("top-level declarations: by brackets and semicolons, a missing } ending at the next declaration's keyword") {
    std::string text = "const a = 1;\n@shape(star)\nobject o {\n    object p { x = \"}\"; }\n// }\nfn f(x: float) -> float = x;\nobject q {\n";
    auto d = topLevelDeclarations(text);
    REQUIRE(d.size() == 4);
    CHECK(text.substr(d[0].begin, d[0].end - d[0].begin) == "const a = 1;");
    CHECK(text.compare(d[1].begin, 12, "@shape(star)") == 0);  // an object's attribute is its own
    CHECK(d[1].unfinished);
    CHECK(text.compare(d[2].begin, 5, "fn f(") == 0);          // o's `}` is missing: fn starts anew
    CHECK_FALSE(d[2].unfinished);
    CHECK(text.compare(d[3].begin, 8, "object q") == 0);
    CHECK(d[3].unfinished);
    auto blanked = blankBroken(text, {});  // the unfinished ones, whatever the errors say
    REQUIRE(blanked);
    CHECK(blanked->size() == text.size());
    CHECK(blanked->find("object o") == std::string::npos);
    CHECK(blanked->find("object q") == std::string::npos);
    CHECK(blanked->find("fn f(x: float)") == text.find("fn f(x: float)"));
    CHECK(blanked->find("const a = 1;") == 0);
}

TEST_CASE("a file opened with a missing } answers in the declarations after it") {
    std::string text = "object a {\n    x = 1;\n\nobject b {\n    pos = vec3(1);\n    point(pos, white, 1);\n}\nspawn b;\n";
    Open s(text);
    json symbols = s.ask("textDocument/documentSymbol", json::object())["result"];
    std::vector<std::string> names;
    for (const json& sym : symbols) names.push_back(sym["name"]);
    CHECK(has(names, "b"));
    CHECK_FALSE(has(names, "a"));
    CHECK(hoverOf(s.at("textDocument/hover", text, at(text, "pos = vec3", 1, 1))).find("pos: vec3") != std::string::npos);
}

TEST_CASE("an edit inside a name: what the last analysis said of it is not shown while the next runs") {
    SlowSession session;  // every analysis slow: reads answer from the last one
    auto& server = session.server;
    auto request = [&](int id, const std::string& method, json params) { return session.request(id, method, std::move(params)); };
    request(1, "initialize", json::object());
    std::string uri = "file:///tmp/inside.psys", text = kFireworks;
    server.handle({{"jsonrpc", "2.0"}, {"method", "textDocument/didOpen"},
                   {"params", {{"textDocument", {{"uri", uri}, {"version", 1}, {"text", text}}}}}});
    auto change = [&](const std::string& now, int version) {
        server.handle({{"jsonrpc", "2.0"}, {"method", "textDocument/didChange"},
                       {"params", {{"textDocument", {{"uri", uri}, {"version", version}}}, {"contentChanges", {{{"text", now}}}}}}});
    };
    auto hoverAt = [&](const std::string& now, uint32_t offset, int id) {
        return request(id, "textDocument/hover", {{"textDocument", {{"uri", uri}}}, {"position", position(SourceFile("x", now), offset)}});
    };
    // `gravity` → `graXvity` (inside the name): no hover for it, nor tokens.
    std::string inside = text;
    inside.insert(at(text, "gravity(0.3)", 1, 3), "X");
    change(inside, 2);
    CHECK(hoverAt(inside, at(inside, "graXvity", 1, 1), 2).is_null());
    // `gravity` → `gravityx` (typed onto its end): the cursor past the old name gets nothing.
    std::string onto = text;
    onto.insert(at(text, "gravity(0.3)", 1, 7), "x");
    change(onto, 3);
    CHECK(hoverAt(onto, at(onto, "gravityx", 1, 8), 3).is_null());
    CHECK(hoverOf(json{{"result", hoverAt(onto, at(onto, "vel = snapshot"), 4)}}).find("vel: vec3") != std::string::npos);
}

TEST_CASE("workspace index: references, rename and symbols reach files no one opened, kept current from file events") {
    TempDir dir;
    std::string lib = "fn bounce(v: float) -> float = -v * 0.8;\n";
    std::string marbles = "import \"lib.psys\";\nobject m {\n    vel = snapshot(bounce(1));\n    pos = origin + "
                          "integrate(vec3(0, vel, 0));\n    point(pos, white, 2);\n}\nspawn m;\n";
    std::string libPath = dir.write("lib.psys", lib);
    dir.write("marbles.psys", marbles);
    std::filesystem::create_directories(dir.path / ".hidden");
    dir.write(".hidden/skip.psys", "import \"../lib.psys\";\nconst k = bounce(2);\n");
    Session s;
    s.request(1, "initialize", {{"initializationOptions", {{"debounceMs", 0}}},
                                {"workspaceFolders", {{{"uri", uriFromPath(dir.path.string())}, {"name", "w"}}}}});
    std::string uri = uriFromPath(libPath);
    s.server.handle({{"jsonrpc", "2.0"}, {"method", "textDocument/didOpen"},
                     {"params", {{"textDocument", {{"uri", uri}, {"version", 1}, {"text", lib}}}}}});
    while (s.server.busy()) s.server.idle();  // the index is built in the background
    json at = {{"textDocument", {{"uri", uri}}}, {"position", {{"line", 0}, {"character", 4}}}};
    json refs = s.request(2, "textDocument/references", at)["result"];
    std::set<std::string> files;
    for (const json& r : refs) files.insert(r["uri"]);
    CHECK(files == std::set<std::string>{uri, uriFromPath((dir.path / "marbles.psys").string())});
    json renamed = at;
    renamed["newName"] = "rebound";
    json edit = s.request(3, "textDocument/rename", renamed)["result"];
    CHECK(edit["changes"].size() == 2);
    CHECK(edit["changes"][uriFromPath((dir.path / "marbles.psys").string())].size() == 1);
    json symbols = s.request(4, "workspace/symbol", {{"query", "m"}})["result"];
    bool m = false;
    for (const json& sym : symbols) m |= sym["name"] == "m";
    CHECK(m);  // marbles' object, never opened
    // A file created on disk (didChangeWatchedFiles): its use is found; deleted: gone.
    std::string more = dir.write("more.psys", "import \"lib.psys\";\nconst k = bounce(3);\n");
    s.server.handle({{"jsonrpc", "2.0"}, {"method", "workspace/didChangeWatchedFiles"},
                     {"params", {{"changes", {{{"uri", uriFromPath(more)}, {"type", 1}}}}}}});
    CHECK(s.request(5, "textDocument/references", at)["result"].size() == refs.size() + 1);
    std::filesystem::remove(more);
    s.server.handle({{"jsonrpc", "2.0"}, {"method", "workspace/didChangeWatchedFiles"},
                     {"params", {{"changes", {{{"uri", uriFromPath(more)}, {"type", 3}}}}}}});
    CHECK(s.request(6, "textDocument/references", at)["result"].size() == refs.size());
    // An unsaved edit to lib (a line added above bounce): marbles' uses are still found,
    // and the declaration's place is the one in the editor's text.
    s.server.handle({{"jsonrpc", "2.0"}, {"method", "textDocument/didChange"},
                     {"params", {{"textDocument", {{"uri", uri}, {"version", 2}}}, {"contentChanges", {{{"text", "\n" + lib}}}}}}});
    json moved = {{"textDocument", {{"uri", uri}}}, {"position", {{"line", 1}, {"character", 4}}}};
    json after = s.request(7, "textDocument/references", moved)["result"];
    CHECK(after.size() == refs.size());
    for (const json& r : after)
        if (r["uri"] == uri) CHECK(r["range"]["start"]["line"] == 1);
}

TEST_CASE("edit map: random line edits, every line kept maps to itself and every line inserted to nothing") {
    uint32_t seed = 12345;
    auto next = [&] { return seed = seed * 1664525u + 1013904223u; };
    for (int round = 0; round < 200; ++round) {
        std::vector<std::string> older;
        for (int i = 0; i < 40; ++i) older.push_back("line " + std::to_string(next() % 7));  // repeats on purpose
        std::vector<std::string> current;
        std::vector<int> from;  // per current line: its older line, or -1 (inserted)
        for (int i = 0; i < 40; ++i) {
            uint32_t r = next() % 10;
            if (r == 0) continue;  // deleted
            if (r == 1) current.push_back("new " + std::to_string(next())), from.push_back(-1);
            current.push_back(older[static_cast<size_t>(i)]), from.push_back(i);
        }
        std::string a, b;
        std::vector<uint32_t> aStart, bStart;
        for (const std::string& l : older) aStart.push_back(static_cast<uint32_t>(a.size())), a += l + "\n";
        for (const std::string& l : current) bStart.push_back(static_cast<uint32_t>(b.size())), b += l + "\n";
        EditMap m(a, b);
        for (size_t j = 0; j < current.size(); ++j) {
            auto back = m.toOlder(bStart[j] + 1);  // a byte inside the line
            if (!back) continue;                   // (inside an edit: not known, never wrong)
            // Wherever it maps, the older text has the same line there; an inserted line's
            // inside maps nowhere.
            CHECK(a.compare(*back - 1, current[j].size() + 1, current[j] + "\n") == 0);
            if (from[j] < 0) FAIL_CHECK("an inserted line maps into the older text: " << current[j]);
        }
    }
}
