#include <doctest/doctest.h>

#include "frontend/diagnostics.h"

using namespace psys;

TEST_CASE("a diagnostic prints location, source line and an underline under its range") {
    SourceManager sources;
    int f = sources.add("fire.psys", "object a {\n    acc = g + tint;\n}\n");
    DiagnosticEngine diags(sources);
    diags.error({f, 21, 29}, "cannot add vec3 and vec4").notes.push_back({{f, 0, 6}, "declared here"});
    CHECK(diags.errorCount() == 1);
    CHECK(diags.render() ==
          "fire.psys:2:11: error: cannot add vec3 and vec4\n"
          " 2 |     acc = g + tint;\n"
          "   |           ^~~~~~~~\n"
          "fire.psys:1:1: note: declared here\n"
          " 1 | object a {\n"
          "   | ^~~~~~\n"
          "1 error generated.\n");
}

TEST_CASE("tabs in the source line are kept in the underline so the caret lines up") {
    SourceManager sources;
    int f = sources.add("t.psys", "\tx = $;\n");
    DiagnosticEngine diags(sources);
    diags.error({f, 5, 6}, "unexpected character '$'");
    CHECK(diags.render().find(" 1 | \tx = $;\n   | \t    ^\n") != std::string::npos);
}

TEST_CASE("an empty range gets one caret — a range past its line is cut at the line end") {
    SourceManager sources;
    int f = sources.add("t.psys", "ab\ncd\n");
    DiagnosticEngine diags(sources);
    diags.error({f, 2, 2}, "here");
    diags.error({f, 0, 5}, "long");
    std::string out = diags.render();
    CHECK(out.find(" 1 | ab\n   |   ^\n") != std::string::npos);
    CHECK(out.find(" 1 | ab\n   | ^~\n") != std::string::npos);
}

TEST_CASE("colour codes only when asked") {
    SourceManager sources;
    int f = sources.add("t.psys", "x\n");
    DiagnosticEngine diags(sources);
    diags.warning({f, 0, 1}, "w");
    CHECK(diags.render(false).find('\x1b') == std::string::npos);
    CHECK(diags.render(true).find("\x1b[1;35mwarning") != std::string::npos);
    CHECK(diags.render(false).find("1 warning generated.") != std::string::npos);
}

TEST_CASE("diagnostics without a location name the tool") {
    SourceManager sources;
    DiagnosticEngine diags(sources);
    diags.error({}, "cannot read `x.psys`: No such file or directory");
    CHECK(diags.render() == "psysc: error: cannot read `x.psys`: No such file or directory\n1 error generated.\n");
}

TEST_CASE("the summary counts errors and warnings") {
    SourceManager sources;
    int f = sources.add("t.psys", "x\n");
    DiagnosticEngine diags(sources);
    diags.error({f, 0, 1}, "a");
    diags.error({f, 0, 1}, "b");
    diags.warning({f, 0, 1}, "c");
    CHECK(diags.render().find("2 errors and 1 warning generated.") != std::string::npos);
}

TEST_CASE("suppressed reports are dropped and not counted") {
    SourceManager sources;
    DiagnosticEngine diags(sources);
    diags.setSuppressed(true);
    diags.error({}, "hidden").notes.push_back({{}, "also hidden"});
    diags.setSuppressed(false);
    CHECK(diags.errorCount() == 0);
    CHECK(diags.all().empty());
}

TEST_CASE("past 50 errors and 50 warnings, the rest are counted and not kept") {
    SourceManager sources;
    int f = sources.add("x.psys", "x\n");
    DiagnosticEngine diags(sources);
    for (int i = 0; i < 70; ++i) diags.error({f, 0, 1}, "bad").notes.push_back({{f, 0, 1}, "a note"});
    for (int i = 0; i < 3; ++i) diags.warning({f, 0, 1}, "odd");
    CHECK(diags.errorCount() == 70);
    CHECK(diags.warningCount() == 3);
    CHECK(diags.all().size() == 53);
    std::string text = diags.render();
    CHECK(text.find("(the first 50 errors and 3 warnings are shown; 20 more errors are not)\n"
                    "70 errors and 3 warnings generated.\n") != std::string::npos);
    // Only the kinds there are, in the singular where one.
    for (int i = 0; i < 48; ++i) diags.warning({f, 0, 1}, "odd");
    CHECK(diags.render().find("(the first 50 errors and 50 warnings are shown; 20 more errors and 1 more warning are not)\n") !=
          std::string::npos);
    DiagnosticEngine warnings(sources);
    for (int i = 0; i < 2499; ++i) warnings.warning({f, 0, 1}, "odd");
    CHECK(warnings.render().find("(the first 50 warnings are shown; 2449 more warnings are not)\n") != std::string::npos);
}

TEST_CASE("a line with control characters or bytes that are not UTF-8 prints as spaces and '?', the caret under its character") {
    SourceManager sources;
    int f = sources.add("x.psys", std::string("a\0b\x01 caf\xE9 \xE2\x86\x92 x\n", 15));
    DiagnosticEngine diags(sources);
    diags.error({f, 13, 14}, "here");
    CHECK(diags.render() == "x.psys:1:14: error: here\n"
                            " 1 | a b  caf? \xE2\x86\x92 x\n"
                            "   |            ^\n"  // under `x`: the arrow is 3 bytes and one character
                            "1 error generated.\n");
}

TEST_CASE("a very long line is shown as a window around the range") {
    SourceManager sources;
    std::string text = std::string(1000, 'a') + " bad " + std::string(1000, 'b') + "\n";
    int f = sources.add("x.psys", text);
    DiagnosticEngine diags(sources);
    diags.error({f, 1001, 1004}, "here");
    std::string shown = diags.render();
    CHECK(shown == "x.psys:1:1002: error: here\n"
                   " 1 | ..." + std::string(59, 'a') + " bad " + std::string(96, 'b') + "...\n"
                   "   |    " + std::string(60, ' ') + "^~~\n"
                   "1 error generated.\n");
}
