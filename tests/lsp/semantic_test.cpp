// Semantic tokens: each name of the main file with what it is, in the protocol's relative
// encoding and UTF-16 columns.
#include <doctest/doctest.h>

#include <map>

#include "lsp_support.h"

using namespace psys;
using namespace psys::lsp;
using namespace psys::lsp::test;
using nlohmann::json;

namespace {

struct Decoded {
    std::string type;
    std::vector<std::string> modifiers;
};

// The tokens by (line, the text they cover), decoded with the server's own legend.
std::map<std::pair<uint32_t, std::string>, Decoded> decode(const json& tokens, const std::string& text) {
    std::vector<std::string> lines;
    for (size_t from = 0, to; from <= text.size(); from = to + 1) {
        to = text.find('\n', from);
        if (to == std::string::npos) to = text.size();
        lines.push_back(text.substr(from, to - from));
    }
    json legend = semanticTokensLegend();
    std::map<std::pair<uint32_t, std::string>, Decoded> out;
    const json& d = tokens["data"];
    REQUIRE(d.size() % 5 == 0);
    uint32_t line = 0, character = 0;
    for (size_t i = 0; i < d.size(); i += 5) {
        line += d[i].get<uint32_t>();
        character = d[i].get<uint32_t>() == 0 ? character + d[i + 1].get<uint32_t>() : d[i + 1].get<uint32_t>();
        Decoded t{legend["tokenTypes"][d[i + 3].get<size_t>()], {}};
        for (size_t bit = 0; bit < legend["tokenModifiers"].size(); ++bit)
            if (d[i + 4].get<unsigned>() & (1u << bit)) t.modifiers.push_back(legend["tokenModifiers"][bit]);
        // ASCII lines here: UTF-16 columns are bytes.
        out[{line, lines[line].substr(character, d[i + 2].get<size_t>())}] = t;
    }
    return out;
}

}  // namespace

TEST_CASE("semantic tokens: an equation, a parameter, a parent read, an extern, a trigger, each its own kind") {
    std::string text = kFireworks;
    text += "trigger boom(at_pos: vec3) {\n    emit rocket(at_pos);\n}\n@integrator(rk4);\nconst k = 2 * pi;\n";
    Analysis a = analyze("/tmp/s.psys", text);
    REQUIRE(a.diagnostics.empty());
    auto tokens = decode(semanticTokens(a), text);
    auto is = [&](uint32_t line, const std::string& name, const std::string& type, std::vector<std::string> mods = {}) {
        INFO(line, ": ", name);
        auto it = tokens.find({line, name});
        REQUIRE(it != tokens.end());
        CHECK(it->second.type == type);
        CHECK(it->second.modifiers == mods);
    };
    is(0, "sparks", "macro", {"declaration"});
    is(6, "sparks", "macro");
    is(1, "gravity", "function", {"declaration"});
    is(1, "m", "parameter");  // its use in the body: the last of the line's two
    is(2, "rocket", "class", {"declaration"});
    is(2, "ivel", "parameter", {"declaration"});
    is(3, "pos", "variable", {"declaration"});
    is(3, "vel", "variable");
    is(3, "origin", "variable", {"readonly", "defaultLibrary"});
    is(3, "integrate", "function", {"defaultLibrary"});
    is(4, "ivel", "parameter");
    is(4, "gravity", "function");
    is(6, "spark", "class");
    is(9, "rocket", "class");
    is(9, "vel", "property");  // `rocket.vel`: read live from the parent
    is(10, "age", "variable", {"defaultLibrary"});
    is(15, "boom", "event", {"declaration"});
    is(16, "at_pos", "parameter");
    is(18, "integrator", "decorator");
    is(18, "rk4", "enumMember", {"defaultLibrary"});
    is(19, "k", "variable", {"declaration", "readonly"});
    // Sorted, none overlapping: every token after the one before.
    json d = semanticTokens(a)["data"];
    for (size_t i = 5; i < d.size(); i += 5) CHECK((d[i] > 0 || d[i + 1] > 0));
}

TEST_CASE("semantic tokens: the server announces them with their legend and answers for an open document") {
    Session s;
    json caps = s.request(1, "initialize")["result"]["capabilities"];
    CHECK(caps["semanticTokensProvider"]["full"]["delta"] == true);
    CHECK(caps["semanticTokensProvider"]["range"] == true);
    CHECK(caps["semanticTokensProvider"]["legend"]["tokenTypes"][0] == "variable");
    s.server.handle({{"jsonrpc", "2.0"},
                     {"method", "textDocument/didOpen"},
                     {"params", {{"textDocument", {{"uri", "file:///tmp/st.psys"}, {"languageId", "psys"}, {"version", 1},
                                                   {"text", std::string(kFireworks)}}}}}});
    json r = s.request(2, "textDocument/semanticTokens/full", {{"textDocument", {{"uri", "file:///tmp/st.psys"}}}});
    CHECK(r["result"]["data"].size() > 100);
}
