// The canonical layout (frontend/format.h): the rules on small cases, and on every sample,
// library file and golden error file that parses: formatting twice changes nothing, and the
// meaning is the same (the IR of a sample, the AST and the diagnostics of an error file).
#include <doctest/doctest.h>

#include <cctype>
#include <filesystem>

#include "driver/compile.h"
#include "frontend/format.h"
#include "frontend/frontend.h"
#include "ir/printer.h"
#include "test_support.h"

namespace psys {
namespace {

std::optional<std::string> format(const std::string& text, std::string* errors = nullptr) {
    SourceManager sources;
    DiagnosticEngine diags(sources);
    auto out = formatSource(sources.add("test.psys", text), sources, diags);
    if (errors) *errors = diags.render(false);
    return out;
}

std::string formatted(const std::string& text) {
    auto out = format(text);
    REQUIRE(out);
    CHECK(format(*out) == *out);
    return *out;
}

std::string irOf(const std::string& path, const std::string& text) {
    SourceManager sources;
    DiagnosticEngine diags(sources);
    auto module = compileText(path, text, sources, diags);
    INFO(diags.render(false));
    REQUIRE(module);
    return ir::print(*module);
}

// What a file means without where: its AST with the positions taken out, and its
// diagnostics' words.
std::string meaningOf(const std::string& path, const std::string& text) {
    SourceManager sources;
    DiagnosticEngine diags(sources);
    std::string out;
    if (auto program = checkText(path, text, sources, diags)) out = printAst(*program, sources);
    for (const Diagnostic& d : diags.all()) out += "\n" + d.message;
    // Take out the AST printer's ` @LINE:COLUMN`s.
    std::string bare;
    for (size_t i = 0; i < out.size(); ++i) {
        size_t j = i;
        while (j < out.size() && out[j] == ' ') ++j;
        if (j + 1 < out.size() && out[j] == '@' && std::isdigit(static_cast<unsigned char>(out[j + 1]))) {
            size_t k = j + 1;
            while (k < out.size() && (std::isdigit(static_cast<unsigned char>(out[k])) || out[k] == ':')) ++k;
            i = k - 1;
            continue;
        }
        bare += out[i];
    }
    return bare;
}

// `text` with every line's leading spaces made one.
std::string squeeze(const std::string& text) {
    std::string out;
    for (size_t i = 0; i < text.size(); ++i) {
        out += text[i];
        if (text[i] == '\n' && i + 1 < text.size() && text[i + 1] == ' ') {
            out += ' ';
            while (i + 1 < text.size() && text[i + 1] == ' ') ++i;
        }
    }
    return out;
}

std::vector<std::filesystem::path> filesIn(const std::string& dir) {
    std::vector<std::filesystem::path> files;
    for (auto& entry : std::filesystem::directory_iterator(dir))
        if (entry.path().extension() == ".psys") files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    return files;
}

TEST_CASE("format: one statement a line, blocks opened on the line and closed alone, four spaces a level") {
    CHECK(formatted("object a{pos=origin;point(pos,white,2);kill when age>1;}spawn a;") ==
          "object a {\n    pos = origin;\n    point(pos, white, 2);\n    kill when age > 1;\n}\nspawn a;\n");
    CHECK(formatted("object a\n{\n\tx   =  1 ;\n  when x>0{kill;}\n}\n") ==
          "object a {\n    x = 1;\n    when x > 0 {\n        kill;\n    }\n}\n");
    CHECK(formatted("object a {}\nobject b {\n\n}\n") == "object a {}\nobject b {}\n");
}

TEST_CASE("format: operators, calls, unary signs, type colons and ternary colons") {
    CHECK(formatted("const a=-1+ -2*(3-+4);") == "const a = -1 + -2 * (3 - +4);\n");
    CHECK(formatted("fn f(x:float,y :vec3)->vec3=x<0?y:-y*x;") ==
          "fn f(x: float, y: vec3) -> vec3 = x < 0 ? y : -y * x;\n");
    CHECK(formatted("object a(p:vec3){v=(p.x,1)->(prev(v).y,!true?2:3);}") ==
          "object a(p: vec3) {\n    v = (p.x, 1) -> (prev(v).y, !true ? 2 : 3);\n}\n");
    CHECK(formatted("extern n:float=3 range(0,10);") == "extern n: float = 3 range(0, 10);\n");
    CHECK(formatted("object a { emit b ( 1 ) at 2 per second count 3 ; }") ==
          "object a {\n    emit b(1) at 2 per second count 3;\n}\n");
}

TEST_CASE("format: each object attribute on a line, a file attribute keeps its semicolon") {
    CHECK(formatted("@integrator(rk4) ;\n@shape(disc) @blend(alpha) object a {}") ==
          "@integrator(rk4);\n@shape(disc)\n@blend(alpha)\nobject a {}\n");
}

TEST_CASE("format: comments stay where they were, trailing comments of consecutive lines line up") {
    std::string in = "// head\n\n\n\nconst a = 1; // one\nconst bb = 22;   // two\n\nconst c = 3;    // three\n"
                     "object o { /* inline */ x = 1;\n  // last\n}\n/* tail\n   spans */\n";
    CHECK(formatted(in) == "// head\n\nconst a = 1;    // one\nconst bb = 22;  // two\n\nconst c = 3;  // three\n"
                           "object o { /* inline */\n    x = 1;\n    // last\n}\n/* tail\n   spans */\n");
    CHECK(formatted("const a = 1; /* b */ const c = 2;") == "const a = 1; /* b */\nconst c = 2;\n");
    CHECK(formatted("object a // why\n{\n}\n") == "object a  // why\n{}\n");
}

TEST_CASE("format: a statement keeps its line breaks, continuation lines indent past the line of the open bracket") {
    std::string in = "object o {\n  x = f(1,\n 2, g(3,\n4),\n  5\n);\n  y = 1 +\n2;\n}\n";
    CHECK(formatted(in) == "object o {\n    x = f(1,\n        2, g(3,\n            4),\n        5\n    );\n"
                           "    y = 1 +\n        2;\n}\n");
    // No blank line inside a statement, nor at either end of a block.
    CHECK(formatted("object o {\n\n  x = 1 +\n\n 2;\n\n}\n") == "object o {\n    x = 1 +\n        2;\n}\n");
}

TEST_CASE("format: a line past the width breaks after a comma or operator, the shallowest that fits, its rest one level in") {
    // An emit of 118 columns: after the comma between its two arguments, not inside them.
    std::string emit = "object o {\n    emit p(vec3(nrand() * 0.3, 0.3, nrand() * 0.3), vec3(nrand() * 0.5, 1 + rand(), "
                       "nrand() * 0.5)) at 10 per second;\n}\nobject p(a: vec3, b: vec3) { point(a, white, 1); }\n";
    std::string out = formatted(emit);
    CHECK(out.find("    emit p(vec3(nrand() * 0.3, 0.3, nrand() * 0.3),\n        vec3(nrand() * 0.5, 1 + rand(), "
                   "nrand() * 0.5)) at 10 per second;\n") != std::string::npos);
    // A fn: after its `=` (the body fits on the next line), never after the `->` of its type.
    std::string fn = "fn ramp(t: float, t0: float, c0: vec4, t1: float, c1: vec4) -> vec4 = mix(c0, c1, clamp((t - t0) "
                     "/ (t1 - t0)));\n";
    CHECK(formatted(fn) == "fn ramp(t: float, t0: float, c0: vec4, t1: float, c1: vec4) -> vec4 =\n"
                           "    mix(c0, c1, clamp((t - t0) / (t1 - t0)));\n");
    // `init -> next` may break after its `->`; a line the author broke keeps its break, and
    // its continuation indents past the piece that holds its open bracket.
    std::string arrow = "object o(ipos: vec3) {\n    (pos, vel) = (ipos, vec3(0)) -> bounce(prev(pos), prev(vel) * "
                        "exp(-1.5 * dt) + vec3(0, -9.8, 0) * dt,\n        vec3(0), dt, 0.5);\n    point(pos, white, "
                        "1);\n}\nfn bounce(p: vec3, v: vec3, a: vec3, dt: float, k: float) -> (vec3, vec3) = (p + v * "
                        "dt, v * k + a);\n";
    std::string arrowOut = formatted(arrow);
    CHECK(arrowOut.find("\n            vec3(0), dt, 0.5);\n") != std::string::npos);
    for (size_t at = 0, end; at < arrowOut.size(); at = end + 1) {  // no line past 100
        end = arrowOut.find('\n', at);
        CHECK(end - at <= 100);
    }
    // Width 0: never broken; a long line with nowhere to break stays as it is.
    SourceManager sources;
    DiagnosticEngine diags(sources);
    LayoutOptions unlimited;
    unlimited.width = 0;
    CHECK(formatSource(sources.add("w.psys", emit), sources, diags, unlimited)->find("nrand() * 0.3),\n") ==
          std::string::npos);
    std::string word = "spawn " + std::string(120, 'a') + ";\n";
    CHECK(formatted(word) == word);
    // Where no break makes the first part fit, the first one is taken: the rest is shorter.
    CHECK(formatted("const " + std::string(120, 'a') + " = 1;\n") == "const " + std::string(120, 'a') + " =\n    1;\n");
}

TEST_CASE("format: a block comment over several lines moves with its code, its own layout kept") {
    // Written two levels in, at column 8; its object is at the top: it moves 4 left, its
    // column of stars and its indented example with it.
    std::string text = "object o {\n        /* A column of stars:\n         *   pos = 1;\n         */\n"
                       "    pos = vec3(1);\n    point(pos, white, 1);\n}\n";
    CHECK(formatted(text) == "object o {\n    /* A column of stars:\n     *   pos = 1;\n     */\n    pos = vec3(1);\n"
                             "    point(pos, white, 1);\n}\n");
    // Moved right: from column 0 into the object.
    std::string right = "object o {\n/* two\n   lines */\n    point(vec3(0), white, 1);\n}\n";
    CHECK(formatted(right) == "object o {\n    /* two\n       lines */\n    point(vec3(0), white, 1);\n}\n");
    // After code on its line: its start is where the code ends.
    std::string after = "const a = 1;    /* one\n                   two */\n";
    CHECK(formatted(after) == "const a = 1; /* one\n" + std::string(16, ' ') + "two */\n");
    // One after another on a line: each from where it starts (formatting again changes nothing).
    formatted("/* a\n   b */ /* c\n   d */\nconst x = 1;\n");
    // Blank lines (CRLF's too) get no trailing spaces.
    CHECK(formatted("object o {\n/* a\r\n\r\n   b */\n    point(vec3(0), white, 1);\n}\n").find(" \r") == std::string::npos);
}

TEST_CASE("format: the line endings and white space of any editor give the same layout") {
    CHECK(formatted("object a {\r\n\tx = 1;\r\n}\r\n") == "object a {\n    x = 1;\n}\n");
    CHECK(formatted("const a = 1;   \n\n\n\n   const b = 2;") == "const a = 1;\n\nconst b = 2;\n");
    CHECK(formatted("") == "");
    CHECK(formatted("// only a comment   ") == "// only a comment\n");
    // Comments line up by characters, not bytes.
    CHECK(formatted("import \"é😀.psys\"; // é😀\nconst tt = 1; // x\n") ==
          "import \"é😀.psys\";  // é😀\nconst tt = 1;      // x\n");
}

TEST_CASE("format: a file with syntax errors is refused with them, never half formatted") {
    std::string errors;
    CHECK_FALSE(format("object a { x = ; }", &errors));
    CHECK(errors.find("error") != std::string::npos);
    CHECK_FALSE(format("const a = 1 $ 2;", &errors));
    CHECK(errors.find("error") != std::string::npos);
    CHECK_FALSE(format("/* never closed", &errors));
    CHECK(errors.find("unterminated comment") != std::string::npos);
}

TEST_CASE("format: every sample and library file is formatted, and formatting keeps its IR") {
    auto files = filesIn(PSYS_SAMPLES_DIR);
    for (auto& f : filesIn(PSYS_LIBRARY_DIR "/std")) files.push_back(f);
    REQUIRE(files.size() > 20);
    for (const auto& path : files) {
        INFO(path.string());
        std::string text = test::readFile(path.string());
        std::string out = formatted(text);
        CHECK(out == text);  // `psysc fmt --write` has been run on them
        // The same meaning from a layout that differs in every gap: one space everywhere.
        std::string squeezed = squeeze(text);
        if (path.parent_path().filename() == "samples")
            CHECK(irOf(path.string(), formatted(squeezed)) == irOf(path.string(), text));
        CHECK(formatted(squeezed) == text);
    }
}

TEST_CASE("format: every golden error file that parses keeps its AST and its diagnostics") {
    int parsed = 0;
    for (const auto& path : filesIn(PSYS_ERRORS_DIR)) {
        INFO(path.string());
        std::string text = test::readFile(path.string());
        auto out = format(text);
        if (!out) continue;
        ++parsed;
        CHECK(format(*out) == *out);
        CHECK(meaningOf(path.string(), *out) == meaningOf(path.string(), text));
    }
    CHECK(parsed > 80);
}

TEST_CASE("format: a UTF-8 byte order mark stays where the file had it") {
    // It compiled, and formatting said "internal error … (please report it)".
    const std::string bom = "\xEF\xBB\xBF";
    auto out = format(bom + "object a {point(vec3(0),white,1);}\nspawn a;\n");
    REQUIRE(out);
    CHECK(*out == bom + "object a {\n    point(vec3(0), white, 1);\n}\nspawn a;\n");
    CHECK(format(*out) == out);
}

}  // namespace
}  // namespace psys
