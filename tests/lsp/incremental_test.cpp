// Re-checking only what an edit can change (lsp/incremental.h): after edits to every
// sample's declarations, the analysis made from the last one answers exactly what a whole
// analysis of the new text answers.
#include <doctest/doctest.h>

#include <fstream>
#include <random>
#include <regex>

#include "frontend/parse_cache.h"
#include "lsp_support.h"

using namespace psys;
using namespace psys::lsp;
using namespace psys::lsp::test;

namespace {

struct Edit {
    std::string what, text;
};

// Edits inside the declaration [begin, end) of `text`: a number changed, an equation added
// (never used), a type error, and the number changed back (from the error).
std::vector<Edit> editsOf(const std::string& text, uint32_t begin, uint32_t end) {
    std::vector<Edit> out;
    std::string piece = text.substr(begin, end - begin);
    std::smatch m;
    if (std::regex_search(piece, m, std::regex(R"([ (,*+-]([0-9]+)\.?[0-9]*)"))) {
        size_t at = begin + size_t(m.position(1));
        std::string changed = text;
        changed.insert(at, "1");
        out.push_back({"a number changed", changed});
    }
    size_t brace = piece.find('{');
    if (piece.find("object ") != std::string::npos && brace != std::string::npos) {
        std::string added = text, broken = text;
        added.insert(begin + brace + 1, "\n    probe_value = 2 * age;");
        broken.insert(begin + brace + 1, "\n    probe_value = vec3(1, 2, 3) + vec4(1, 2, 3, 4);");
        out.push_back({"an equation added", added});
        out.push_back({"a type error", broken});
        out.push_back({"the type error fixed", added});
    }
    return out;
}

}  // namespace

TEST_CASE("incremental analysis: what a whole analysis answers, after edits to every sample's declarations") {
    int samples = 0, edits = 0, incremental = 0;
    for (const auto& e : std::filesystem::directory_iterator(PSYS_SAMPLES_DIR)) {
        if (e.path().extension() != ".psys") continue;
        std::string path = e.path().string(), text = slurp(path);
        CAPTURE(path);
        ParseCache cache;
        auto last = std::make_shared<Analysis>(analyze(path, text, {.cache = &cache}));
        std::vector<TopDeclaration> tops = topLevelDeclarations(text);
        // (Four declarations a file, spread over it: the test's time.)
        size_t stride = std::max<size_t>(1, tops.size() / 4);
        for (size_t k = 0; k < tops.size(); k += stride) {
            for (const Edit& edit : editsOf(text, k == 0 ? 0 : tops[k - 1].end, tops[k].end)) {
                CAPTURE(edit.what);
                CAPTURE(k);
                Analysis again = analyze(path, edit.text, {.passes = false, .cache = &cache, .previous = last.get()});
                CHECK(everything(again) == everything(analyze(path, edit.text, {.passes = false})));
                ++edits;
                incremental += again.incremental;
                // The next edit from this one's analysis (as an editor's are).
                if (again.parsed) last = std::make_shared<Analysis>(std::move(again));
                cache.sweep();
            }
        }
        ++samples;
    }
    CHECK(samples > 20);
    MESSAGE(edits << " edits, " << incremental << " analysed incrementally");
    // Most edits are re-checked by declaration (what cannot be is analysed whole).
    CHECK(incremental * 2 > edits);
}

TEST_CASE("incremental analysis: an edit inside one of 300 objects re-checks it alone, and what reads it") {
    std::string text = "fn lift(m: float) -> vec3 = vec3(0, m, 0);\n";
    for (int i = 0; i < 300; ++i)
        text += fmt::format("object o{0}(v: vec3) {{\n    pos = origin + integrate(vel);\n    vel = v + integrate(lift({1}));\n"
                            "    glow = age * 2;\n    point(pos, white, 2);\n    kill when age > 2;\n}}\n",
                            i, i % 5);
    text += "object reader(v: vec3) {\n    pos = origin + integrate(v) + near_sum(o7, 2, other.glow);\n"
            "    point(pos, white, 2);\n}\nspawn o0(vec3(0, 1, 0));\nspawn reader(vec3(0));\n";
    std::string path = (std::filesystem::temp_directory_path() / "incremental.psys").string();
    ParseCache cache;
    Analysis first = analyze(path, text, {.passes = false, .cache = &cache});
    REQUIRE(first.parsed);
    auto check = [&](const std::string& edited, bool incremental) {
        Analysis again = analyze(path, edited, {.passes = false, .cache = &cache, .previous = &first});
        CHECK(again.incremental == incremental);
        CHECK(everything(again) == everything(analyze(path, edited, {.passes = false})));
        return again;
    };
    std::string edited = text;
    size_t o100 = edited.find("object o100(");
    edited.replace(edited.find("lift(0)", o100), 7, "lift(0.5)");
    check(edited, true);
    // o7's `glow` read by the reader's fold: renaming it is an error at the reader, and the
    // clean program's warnings that an equation is never used go with it.
    edited = text;
    size_t o7 = edited.find("object o7(");
    edited.replace(edited.find("glow = age", o7), 4, "glows");
    Analysis renamed = check(edited, true);
    CHECK(first.hiddenWarnings + first.diagnostics.size() > 300);
    CHECK(std::none_of(renamed.diagnostics.begin(), renamed.diagnostics.end(),
                       [](const Diagnostic& d) { return d.severity == Severity::Warning; }));
    // Renamed back, from the analysis with the error: clean again, every warning back.
    Analysis back = analyze(path, text, {.passes = false, .cache = &cache, .previous = &renamed});
    CHECK(back.incremental);
    CHECK(everything(back) == everything(first));
    CHECK(std::any_of(renamed.diagnostics.begin(), renamed.diagnostics.end(), [](const Diagnostic& d) {
        return d.severity == Severity::Error && d.message.find("glow") != std::string::npos;
    }));
    // The reader's fold over o7 changed to one over o8 reading `pos`: o7's `glow` is read by
    // nothing then (what the reader read before the edit is checked again, with every reader).
    edited = text;
    edited.replace(edited.find("near_sum(o7, 2, other.glow)"), 27, "near_sum(o8, 2, other.pos)");
    auto unread = [](const Analysis& a) {
        return std::count_if(a.diagnostics.begin(), a.diagnostics.end(),
                             [](const Diagnostic& d) { return d.message == "equation `glow` is never used"; });
    };
    CHECK(unread(check(edited, true)) == unread(first) + 1);
    // A new object: a new name, analysed whole.
    Analysis whole = analyze(path, text + "object extra { point(origin, white, 1); }\n",
                             {.passes = false, .cache = &cache, .previous = &first});
    CHECK_FALSE(whole.incremental);
}

TEST_CASE("incremental analysis: what a whole analysis answers, after random edits to every sample") {
    // Each edit inside one declaration, one after another from the last analysis that
    // parsed: a name replaced by another of the file's (a type, a function, an equation,
    // a keyword), a word deleted, a line doubled. Many break the program; some do not parse.
    std::mt19937 random(20261203);
    auto pick = [&](size_t n) { return std::uniform_int_distribution<size_t>(0, n - 1)(random); };
    int edits = 0, incremental = 0;
    const std::regex word(R"([A-Za-z_][A-Za-z0-9_]*)");
    for (const auto& e : std::filesystem::directory_iterator(PSYS_SAMPLES_DIR)) {
        if (e.path().extension() != ".psys") continue;
        std::string path = e.path().string(), text = slurp(path);
        CAPTURE(path);
        ParseCache cache;
        auto last = std::make_shared<Analysis>(analyze(path, text, {.passes = false, .cache = &cache}));
        for (int round = 0; round < 8; ++round) {
            std::vector<std::pair<size_t, size_t>> words;  // [begin, length) of each word
            for (auto it = std::sregex_iterator(text.begin(), text.end(), word); it != std::sregex_iterator(); ++it)
                words.emplace_back(size_t(it->position()), size_t(it->length()));
            if (words.empty()) break;
            auto [at, length] = words[pick(words.size())];
            std::string edited = text;
            switch (pick(3)) {
                case 0: {
                    auto [from, n] = words[pick(words.size())];
                    edited.replace(at, length, text.substr(from, n));
                    break;
                }
                case 1: edited.erase(at, length); break;
                default: {
                    size_t lineBegin = text.rfind('\n', at), lineEnd = text.find('\n', at);
                    lineBegin = lineBegin == std::string::npos ? 0 : lineBegin + 1;
                    if (lineEnd == std::string::npos) lineEnd = text.size();
                    edited.insert(lineBegin, text.substr(lineBegin, lineEnd - lineBegin) + "\n");
                }
            }
            CAPTURE(edited);
            Analysis again = analyze(path, edited, {.passes = false, .cache = &cache, .previous = last.get()});
            REQUIRE(everything(again) == everything(analyze(path, edited, {.passes = false})));
            ++edits;
            incremental += again.incremental;
            if (again.parsed && !again.recovered) last = std::make_shared<Analysis>(std::move(again));
            text = std::move(edited);
            cache.sweep();
        }
    }
    MESSAGE(edits << " random edits, " << incremental << " analysed incrementally");
    CHECK(incremental * 4 > edits);
}

TEST_CASE("incremental analysis: what a did-you-mean and an import's quick fix draw on is the whole program's") {
    auto dir = std::filesystem::temp_directory_path() / "psys-incremental";
    std::filesystem::create_directories(dir);
    std::string path = (dir / "main.psys").string();
    // An error elsewhere keeps the program unclean before and after each edit.
    std::string text = "const speed = 2;\nobject Spark { x = 1; point(origin, white, 1); }\n"
                       "object A { x = 1; point(origin, white, 1); }\nobject B { y = nope; point(origin, white, 1); }\n"
                       "spawn A;\n";
    ParseCache cache;
    Analysis first = analyze(path, text, {.passes = false, .cache = &cache});
    auto check = [&](const std::string& from, const std::string& to, const std::string& expected) {
        std::string edited = text;
        edited.replace(edited.find(from), from.size(), to);
        Analysis again = analyze(path, edited, {.passes = false, .cache = &cache, .previous = &first});
        CHECK(again.incremental);
        CHECK(everything(again) == everything(analyze(path, edited, {.passes = false})));
        CHECK(everything(again).find(expected) != std::string::npos);
    };
    check("object A { x = 1;", "object A { x = sped;", "did you mean `speed`?");
    check("object A { x = 1; point(origin, white, 1); }", "object A { x = 1; point(origin, white, 1); emit Sprak; }",
          "did you mean `Spark`?");
    // std/color.psys declares ramp2: the fix imports it at the top of the file.
    check("object A { x = 1;", "object A { x = ramp2(1);", "fix Import \"std/color.psys\" 0:0-0");

    // An imported file that names the main file's declarations: analysed whole.
    std::ofstream(dir / "lib.psys") << "fn g() -> float = scale * 2;\n";
    std::string importing = "import \"lib.psys\";\nconst scale = 1;\nobject A { y = g(); point(origin, white, 1); }\nspawn A;\n";
    Analysis base = analyze(path, importing, {.passes = false, .cache = &cache});
    std::string edited = importing;
    edited.replace(edited.find("const scale = 1"), 15, "const scale = vec3(1, 1, 1)");
    Analysis again = analyze(path, edited, {.passes = false, .cache = &cache, .previous = &base});
    CHECK_FALSE(again.incremental);
    CHECK(everything(again) == everything(analyze(path, edited, {.passes = false})));
    std::filesystem::remove_all(dir);
}
