// The outline (textDocument/documentSymbol): what it lists, and its JSON text, written
// directly (lsp/features.cpp), against the tree the JSON library would build.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "lsp/analysis.h"
#include "lsp/features.h"
#include "lsp/positions.h"
#include "lsp_support.h"

using namespace psys;
using namespace psys::lsp;
using namespace psys::lsp::test;
using nlohmann::json;

TEST_CASE("document symbols: objects with their parameters, equations and nested objects") {
    Analysis a = analyze("/tmp/fw.psys", kFireworks);
    json symbols = json::parse(documentSymbols(a));
    std::vector<std::string> top;
    for (const json& s : symbols) top.push_back(s["name"]);
    CHECK(top == std::vector<std::string>{"sparks", "gravity", "rocket"});
    const json& rocket = symbols[2];
    CHECK(rocket["kind"] == 5);
    std::vector<std::string> inside;
    for (const json& c : rocket["children"]) inside.push_back(c["name"]);
    CHECK(inside == std::vector<std::string>{"ivel", "pos", "vel", "spark"});
    CHECK(rocket["children"][1]["detail"] == "pos: vec3");
    CHECK(rocket["children"][3]["children"].size() == 2);  // spark's ipos and pos
}

namespace {

// The outline as a tree, built from the symbols with the JSON library (what the text
// written directly must parse into).
json outlineTree(const SourceFile& f, const std::vector<Symbol>& symbols) {
    json out = json::array();
    for (const Symbol& s : symbols) {
        json j = {{"name", s.name}, {"kind", static_cast<int>(s.kind)}, {"range", range(f, s.range.begin, s.range.end)},
                  {"selectionRange", range(f, s.selection.begin, s.selection.end)}, {"children", outlineTree(f, s.children)}};
        if (!s.detail.empty()) j["detail"] = s.detail;
        out.push_back(j);
    }
    return out;
}

}  // namespace

TEST_CASE("document symbols: the JSON text written directly is the tree's, on every sample and odd names") {
    for (const auto& e : std::filesystem::directory_iterator(PSYS_SAMPLES_DIR)) {
        if (e.path().extension() != ".psys") continue;
        std::ifstream in(e.path());
        std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        Analysis a = analyze(e.path().string(), text);
        CAPTURE(e.path().string());
        REQUIRE(a.parsed);
        CHECK(json::parse(documentSymbols(a)) == outlineTree(a.sources->file(a.mainFile), a.symbols));
        CHECK(documentSymbols(a) == outlineTree(a.sources->file(a.mainFile), a.symbols).dump());
    }
    // Quotes, backslashes, control characters and UTF-8 in a name or detail, on a line with
    // characters outside the BMP before it (UTF-16 columns).
    SourceFile f("odd.psys", "😀 x\n\"y\"\n");
    Symbol odd{"a\"b\\c\n\t\x01é", "d\re", SymbolKind::Class, {0, 5, 9}, {0, 5, 6}, {}};
    odd.children.push_back({"child", "", SymbolKind::Field, {0, 6, 7}, {0, 6, 7}, {}});
    CHECK(documentSymbols(f, {odd}) == outlineTree(f, {odd}).dump());
}
