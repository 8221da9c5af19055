// The server's edits: quick fixes (code actions) for the fix-its the front end and the
// passes attach to diagnostics, and formatting. Each fix is applied and the file checked
// again: the diagnostic it fixes is gone.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include <fmt/format.h>

#include "lsp/positions.h"
#include "lsp/transport.h"
#include "lsp_support.h"

using namespace psys;
using namespace psys::lsp;
using namespace psys::lsp::test;
using nlohmann::json;

namespace {

// `text` with one protocol TextEdit applied.
std::string applied(const std::string& text, const json& edit) {
    SourceFile f("x.psys", text);
    uint32_t begin = offsetOf(f, edit["range"]["start"]), end = offsetOf(f, edit["range"]["end"]);
    return text.substr(0, begin) + edit["newText"].get<std::string>() + text.substr(end);
}

// The quick fixes offered anywhere in the main file.
json actionsOf(const Analysis& a, const std::string& text) {
    return codeActions(a, 0, static_cast<uint32_t>(text.size()));
}

std::string fixed(const std::string& path, const std::string& text, const json& action) {
    json changes = action["edit"]["changes"];
    REQUIRE(changes.size() == 1);
    CHECK(changes.begin().key() == uriFromPath(path));
    REQUIRE(changes.begin().value().size() == 1);
    return applied(text, changes.begin().value()[0]);
}

}  // namespace

TEST_CASE("quick fix: a did-you-mean changes the name, for a name and for a member") {
    std::string text = "object a {\n    velo = 1;\n    point(vec3(velo2), white, 2);\n    emit b count 1;\n"
                       "    object b {\n        point(vec3(a.vel), white, 2);\n    }\n}\nspawn a;\n";
    Analysis a = analyze("/tmp/q.psys", text);
    json actions = actionsOf(a, text);
    REQUIRE(actions.size() == 2);
    CHECK(actions[0]["title"] == "Change to `velo`");
    CHECK(actions[0]["kind"] == "quickfix");
    CHECK(actions[0]["isPreferred"] == true);
    // Through the server, with the cursor past the typo on its line: the client's
    // diagnostics at the cursor say which fixes it wants.
    Session s;
    s.request(1, "initialize");
    s.server.handle({{"jsonrpc", "2.0"}, {"method", "textDocument/didOpen"},
                     {"params", {{"textDocument", {{"uri", "file:///tmp/q.psys"}, {"languageId", "psys"},
                                                   {"version", 1}, {"text", text}}}}}});
    json cursor = {{"line", 2}, {"character", 25}};
    json none = s.request(2, "textDocument/codeAction", {{"textDocument", {{"uri", "file:///tmp/q.psys"}}},
                                                         {"range", {{"start", cursor}, {"end", cursor}}},
                                                         {"context", {{"diagnostics", json::array()}}}});
    CHECK(none["result"].empty());
    json shown = actions[0]["diagnostics"][0];
    json some = s.request(3, "textDocument/codeAction", {{"textDocument", {{"uri", "file:///tmp/q.psys"}}},
                                                         {"range", {{"start", cursor}, {"end", cursor}}},
                                                         {"context", {{"diagnostics", {shown}}}}});
    REQUIRE(some["result"].size() == 1);
    CHECK(some["result"][0]["title"] == "Change to `velo`");
    CHECK(actions[0]["diagnostics"][0]["message"].get<std::string>().find("did you mean `velo`") != std::string::npos);
    std::string once = fixed("/tmp/q.psys", text, actions[0]);
    CHECK(once.find("vec3(velo)") != std::string::npos);
    std::string twice = fixed("/tmp/q.psys", once, actionsOf(analyze("/tmp/q.psys", once), once)[0]);
    CHECK(twice.find("a.velo)") != std::string::npos);
    CHECK(analyze("/tmp/q.psys", twice).diagnostics.empty());
    // Only the fixes of the diagnostics the range meets.
    CHECK(codeActions(a, 0, at(text, "velo = 1")).empty());
    CHECK(codeActions(a, at(text, "velo2"), at(text, "velo2")).size() == 1);
}

TEST_CASE("quick fix: a standard library name the file does not import adds the import after the others") {
    TempDir dir;
    std::string text = "// Falls.\nimport \"std/color.psys\";\n\nobject a {\n    pos = origin + integrate(vel);\n"
                       "    vel = integrate(earth_gravity);\n    point(pos, white, 2);\n}\nspawn a;\n";
    std::string path = dir.write("fall.psys", text);
    Analysis a = analyze(path, text);
    REQUIRE(a.diagnostics.size() == 1);
    CHECK(a.diagnostics[0].message.find("declares it in std/forces.psys") != std::string::npos);
    json actions = actionsOf(a, text);
    REQUIRE(actions.size() == 1);
    CHECK(actions[0]["title"] == "Import \"std/forces.psys\"");
    std::string out = fixed(path, text, actions[0]);
    CHECK(out.find("import \"std/color.psys\";\nimport \"std/forces.psys\";\n\nobject a") != std::string::npos);
    CHECK(analyze(path, out).diagnostics.empty());
    // Without an import, before the first declaration.
    std::string bare = "object a {\n    point(earth_gravity, white, 2);\n}\nspawn a;\n";
    std::string bareOut = fixed(path, bare, actionsOf(analyze(path, bare), bare)[0]);
    CHECK(bareOut.starts_with("import \"std/forces.psys\";\nobject a {"));
    CHECK(analyze(path, bareOut).diagnostics.empty());
}

TEST_CASE("quick fix: an unstable decay gets the stable integrators and a short enough step") {
    std::string text = "object drag {\n    vel = vec3(0, 10, 0) + integrate(vec3(0, -9.8, 0) - 180 * vel);\n"
                       "    point(vel, white, 1);\n}\nspawn drag;\n";
    Analysis a = analyze("/tmp/w.psys", text);
    json actions = actionsOf(a, text);
    REQUIRE(actions.size() == 3);
    CHECK(actions[0]["title"] == "Add @integrator(exponential)");
    CHECK(actions[1]["title"] == "Add @integrator(exact)");
    CHECK(actions[2]["title"].get<std::string>().starts_with("Add @step(1/"));
    for (const json& action : actions) {
        std::string out = fixed("/tmp/w.psys", text, action);
        INFO(out);
        CHECK(out.starts_with("@"));
        CHECK(analyze("/tmp/w.psys", out).diagnostics.empty());
    }
    // An @integrator already there is replaced, in place and indented as it was.
    std::string nested = "object outer {\n    @integrator(euler)\n    object drag {\n"
                         "        vel = vec3(0, 10, 0) + integrate(vec3(0, -9.8, 0) - 180 * vel);\n"
                         "        point(vel, white, 1);\n    }\n    emit drag count 1;\n    kill when age > 1;\n}\n"
                         "spawn outer;\n";
    json again = actionsOf(analyze("/tmp/w.psys", nested), nested);
    REQUIRE(again.size() == 3);
    CHECK(again[0]["title"] == "Use @integrator(exponential)");
    CHECK(fixed("/tmp/w.psys", nested, again[0]).find("    @integrator(exponential)\n    object drag") !=
          std::string::npos);
    CHECK(fixed("/tmp/w.psys", nested, again[2]).find("    @step(1/95)\n    @integrator(euler)\n    object drag") !=
          std::string::npos);
}

TEST_CASE("formatting: one edit over what changes, nothing for a formatted file, refused with the reason on a syntax error") {
    Session s;
    s.request(1, "initialize");
    std::string text = "// é😀 first\nobject a{pos=origin;\n point(pos,white,2);}\nspawn a;\n";
    s.server.handle({{"jsonrpc", "2.0"},
                     {"method", "textDocument/didOpen"},
                     {"params", {{"textDocument", {{"uri", "file:///tmp/f.psys"}, {"languageId", "psys"}, {"version", 1},
                                                   {"text", text}}}}}});
    json r = s.request(2, "textDocument/formatting",
                       {{"textDocument", {{"uri", "file:///tmp/f.psys"}}}, {"options", {{"tabSize", 4}, {"insertSpaces", true}}}});
    REQUIRE(r["result"].size() == 1);
    CHECK(r["result"][0]["range"]["start"] == json{{"line", 1}, {"character", 8}});
    std::string out = applied(text, r["result"][0]);
    CHECK(out == "// é😀 first\nobject a {\n    pos = origin;\n    point(pos, white, 2);\n}\nspawn a;\n");
    CHECK(std::get<json>(formatting("/tmp/f.psys", out)).empty());
    s.server.handle({{"jsonrpc", "2.0"},
                     {"method", "textDocument/didChange"},
                     {"params", {{"textDocument", {{"uri", "file:///tmp/f.psys"}, {"version", 2}}},
                                 {"contentChanges", {{{"text", "object a { x = ; }"}}}}}}});
    json bad = s.request(3, "textDocument/formatting", {{"textDocument", {{"uri", "file:///tmp/f.psys"}}}});
    CHECK(bad["error"]["code"] == error::kRequestFailed);
    CHECK(bad["error"]["message"].get<std::string>().find("fix the syntax first (line 1:") != std::string::npos);
    CHECK(s.request(4, "initialize")["error"]["code"] == error::kInvalidRequest);  // the session still answers
}

TEST_CASE("diagnostics: a type error covers the operands that disagree, in UTF-16 columns") {
    std::string text = "object a {\n    /* é😀 */ x = vec3(1) + vec4(1);\n    point(vec3(x), white, 1);\n}\nspawn a;\n";
    Analysis a = analyze("/tmp/t.psys", text);
    json d = diagnosticsByUri(a)["file:///tmp/t.psys"];
    REQUIRE(d.size() == 1);
    CHECK(d[0]["message"].get<std::string>().find("cannot add vec3 and vec4") != std::string::npos);
    // `/* é😀 */` is 9 UTF-16 units: `vec3(1)` starts at 18, `vec4(1)` ends at 35.
    CHECK(d[0]["range"] == json{{"start", {{"line", 1}, {"character", 18}}}, {"end", {{"line", 1}, {"character", 35}}}});
}

namespace {

}  // namespace

TEST_CASE("analysis through a document's parse cache: what a fresh analysis answers, on every sample, after edits") {
    int samples = 0;
    for (const auto& e : std::filesystem::directory_iterator(PSYS_SAMPLES_DIR)) {
        if (e.path().extension() != ".psys") continue;
        std::string path = e.path().string(), text = slurp(path);
        CAPTURE(path);
        ParseCache cache;
        CHECK(everything(analyze(path, text, {.cache = &cache})) == everything(analyze(path, text)));
        // Every declaration moved by a line; then one broken (its hovers carried by the salvage).
        for (std::string edit : {"// moved\n" + text, "// moved\nobject broken { pos = ; }\n" + text}) {
            cache.sweep();
            CHECK(everything(analyze(path, edit, {.salvage = true, .cache = &cache})) ==
                  everything(analyze(path, edit, {.salvage = true})));
        }
        ++samples;
    }
    CHECK(samples > 20);
}
