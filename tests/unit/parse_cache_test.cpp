// Parsing through a ParseCache (frontend/parse_cache.h): the same checked tree and the same
// diagnostics as a parse of the whole file, for a cold cache and after edits through a
// warm one, on every sample, library file, test program and golden-error file.
#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "frontend/format.h"
#include "frontend/frontend.h"
#include "frontend/loader.h"
#include "frontend/parse.h"
#include "frontend/parse_cache.h"
#include "test_support.h"

using namespace psys;
namespace fs = std::filesystem;

namespace {

// The checked tree as `--emit=ast` prints it (every declaration's, equation's and
// command's place), or the diagnostics where there are errors.
std::string parsed(const std::string& path, const std::string& text, ParseCache* cache) {
    SourceManager sources;
    DiagnosticEngine diags(sources);
    auto program = loadProgramFromText(path, text, sources, diags, nullptr, cache);
    if (program) checkProgram(*program, diags);
    std::string out = diags.render();
    if (program && diags.errorCount() == 0) out += printAst(*program, sources);
    return out;
}

std::vector<fs::path> sources() {
    std::vector<fs::path> out;
    for (const char* dir : {PSYS_SAMPLES_DIR, PSYS_PROGRAMS_DIR, PSYS_ERRORS_DIR, PSYS_LIBRARY_DIR "/std"})
        for (const auto& e : fs::directory_iterator(dir))
            if (e.path().extension() == ".psys") out.push_back(e.path());
    std::sort(out.begin(), out.end());
    return out;
}

// Edits a person makes: a line above everything (every declaration moves), a number
// changed in the middle, a declaration's closing bracket removed, and back.
std::vector<std::string> edited(const std::string& text) {
    std::vector<std::string> out{"// a new first line\n" + text};
    std::string number = text;
    if (size_t at = number.find_first_of("0123456789", number.size() / 2); at != std::string::npos) number[at] = '7';
    out.push_back(number);
    std::string unclosed = text;
    if (size_t at = unclosed.find("}\n", unclosed.size() / 3); at != std::string::npos) unclosed.erase(at, 1);
    out.push_back(unclosed);
    out.push_back(text);
    return out;
}

}  // namespace

TEST_CASE("a parse through the cache is the whole file's parse: every sample, library and test file, edited") {
    int files = 0;
    for (const fs::path& path : sources()) {
        std::string text = test::readFile(path.string());
        ParseCache cache;
        CAPTURE(path.string());
        CHECK(parsed(path.string(), text, &cache) == parsed(path.string(), text, nullptr));
        for (const std::string& edit : edited(text)) {
            cache.sweep();
            CHECK(parsed(path.string(), edit, &cache) == parsed(path.string(), edit, nullptr));
        }
        ++files;
    }
    CHECK(files > 150);
}

TEST_CASE("the layout from the cache's tokens is the layout from lexing: every file that parses, and re-indented") {
    int laidOut = 0;
    for (const fs::path& path : sources()) {
        std::string text = test::readFile(path.string());
        std::string shallow = text;
        for (size_t at = 0; (at = shallow.find("\n    ", at)) != std::string::npos; at += 3) shallow.replace(at, 5, "\n  ");
        for (const std::string& t : {text, shallow}) {
            ParseCache cache;
            if (parsed(path.string(), t, &cache).find("error") != std::string::npos) continue;
            auto tokens = cache.tokens(t);
            CAPTURE(path.string());
            REQUIRE(tokens);
            SourceManager sources;
            DiagnosticEngine diags(sources);
            int file = sources.add(path.string(), t);
            LayoutOptions fromCache;
            fromCache.tokens = &*tokens;
            CHECK(formatSource(file, sources, diags, fromCache) == formatSource(file, sources, diags));
            ++laidOut;
        }
    }
    CHECK(laidOut > 100);
    // A text the cache has not seen all of: no tokens.
    ParseCache cache;
    parsed("t.psys", "object a { point(vec3(0)); }\nspawn a;\n", &cache);
    CHECK(cache.tokens("object a { point(vec3(0)); }\nspawn a;\n"));
    CHECK_FALSE(cache.tokens("object b { point(vec3(0)); }\nspawn a;\n"));
    CHECK_FALSE(cache.tokens("object a { point(vec3(0)); }\nspawn a;\nobject"));
}

TEST_CASE("an edit inside one declaration parses that declaration only") {
    std::string text;
    for (int i = 0; i < 50; ++i)
        text += "object o" + std::to_string(i) + " {\n    pos = vec3(" + std::to_string(i) + ", 0, 0);\n    point(pos);\n}\n\n";
    text += "spawn o0;\n";
    ParseCache cache;
    parsed("t.psys", text, &cache);
    CHECK(cache.counts().parsed == 51);
    CHECK(cache.counts().copied == 0);
    cache.sweep();
    std::string edit = text;
    edit.replace(edit.find("vec3(20,"), 8, "vec3(21,");
    CHECK(parsed("t.psys", edit, &cache) == parsed("t.psys", edit, nullptr));
    CHECK(cache.counts().parsed == 52);
    CHECK(cache.counts().copied == 50);
    // The text before the edit is kept a sweep longer (an analysis may start from either),
    // then forgotten.
    cache.sweep();
    CHECK(cache.counts().kept == 52);
    parsed("t.psys", edit, &cache);
    cache.sweep();
    CHECK(cache.counts().kept == 51);
}

TEST_CASE("a syntax error through the cache: the same errors, and the declarations after it still reused") {
    std::string text = "object a {\n    pos = vec3(1, 0, 0);\n    point(pos);\n}\n\n"
                       "object b {\n    pos = vec3(2, 0, 0);\n    point(pos);\n}\n\n"
                       "object c {\n    pos = vec3(3, 0, 0);\n    point(pos);\n}\nspawn a;\n";
    ParseCache cache;
    parsed("t.psys", text, &cache);
    for (std::string broken : {std::string("    pos = vec3(2, 0, 0)\n"), std::string("    pos = vec3(2, 0, 0;\n"),
                               std::string("    pos = ;\n"), std::string("    pos = vec3(2, 0, 0);\n}\n}\n")}) {
        std::string edit = text;
        edit.replace(edit.find("    pos = vec3(2, 0, 0);\n"), 25, broken);
        std::string whole = parsed("t.psys", edit, nullptr);
        CAPTURE(edit);
        CHECK(whole.find("error") != std::string::npos);
        CHECK(parsed("t.psys", edit, &cache) == whole);
    }
    // Back to the text that parses: nothing to parse again.
    int before = cache.counts().parsed;
    CHECK(parsed("t.psys", text, &cache) == parsed("t.psys", text, nullptr));
    CHECK(cache.counts().parsed == before);
}

TEST_CASE("byte order marks and white space the lexer does not skip: through the cache as in a whole parse") {
    std::string bom(kByteOrderMark);
    for (const std::string& text : {bom + "object o { point(vec3(zork), white, 1); }\nspawn o;\n",
                                    "const a = 1;" + bom + "const b = 2;\n", "const a = 1;\n" + bom + "const b = 2;\n",
                                    std::string("spawn comet;\n\f"), std::string("const a = 1;\v\nconst b = 2;\n")}) {
        CAPTURE(text);
        ParseCache cache;
        std::string whole = parsed("t.psys", text, nullptr);
        CHECK(parsed("t.psys", text, &cache) == whole);
        cache.sweep();
        CHECK(parsed("t.psys", text, &cache) == whole);
    }
    // A mark at the start of a file is not a character of it: `zork` is where it is.
    SourceManager sources;
    DiagnosticEngine diags(sources);
    std::string text = bom + "object o { point(vec3(zork), white, 1); }\nspawn o;\n";
    checkText("t.psys", text, sources, diags);
    REQUIRE(diags.errorCount() == 1);
    CHECK(text.substr(diags.all()[0].range.begin, 4) == "zork");
}

TEST_CASE("top-level declarations: by brackets and semicolons, attributes with their object") {
    std::string text = "import \"std/forces.psys\";\n@integrator(rk4);\n// a comment; with a semicolon\n"
                       "@step(1/60)\nobject a { pos = vec3(1, 0, 0); /* } */ point(pos, \"}\"); }\n"
                       "fn f(x: float) { let y = x; y }\nspawn a;\n";
    auto tops = topLevelDeclarations(text);
    std::vector<std::string> got;
    for (auto [begin, end, unfinished] : tops) got.push_back(text.substr(begin, end - begin) + (unfinished ? " …" : ""));
    CHECK(got == std::vector<std::string>{"import \"std/forces.psys\";", "@integrator(rk4);",
                                          "@step(1/60)\nobject a { pos = vec3(1, 0, 0); /* } */ point(pos, \"}\"); }",
                                          "fn f(x: float) { let y = x; y }", "spawn a;"});
}
