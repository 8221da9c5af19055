// Syntax errors are worded for people, located, and never crash the front end.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "test_support.h"
#include "tests/run_length.h"

using namespace psys;

namespace {

// ANTLR's own phrasing must never reach a user.
void checkWording(const std::string& output) {
    CHECK(output.find("mismatched input") == std::string::npos);
    CHECK(output.find("extraneous input") == std::string::npos);
    CHECK(output.find("no viable alternative") == std::string::npos);
    CHECK(output.find("expecting") == std::string::npos);
    CHECK(output.find("<EOF>") == std::string::npos);
    CHECK(output.find("T__") == std::string::npos);
}

}  // namespace

TEST_CASE("a missing semicolon is reported after the previous token") {
    auto c = test::check("object a {\n    x = 1\n    y = 2;\n}\n");
    CHECK_FALSE(c.ok());
    CHECK(c.output.find("test.psys:2:10: error: expected ';' at end of equation") != std::string::npos);
}

TEST_CASE("several syntax errors in one run") {
    auto c = test::check("object a {\n    x = 1 +;\n    y = 2 *;\n    z = ;\n}\n");
    CHECK(c.diags->errorCount() == 3);
    checkWording(c.output);
}

TEST_CASE("a keyword where a name belongs says so") {
    auto c = test::check("object emit { point(origin, red, 1); }");
    CHECK(c.output.find("found the keyword 'emit', which is reserved") != std::string::npos);
}

// Every 13th cut in the release build (the suite `long`: scripts/test.sh runs it there);
// every 41st under the sanitizers, where a parse costs ten times as much and a memory error
// on an error path shows at any cut of the kind (the fuzzers try cuts at random too).
TEST_CASE("truncated and damaged samples give located, worded errors and never crash" * doctest::test_suite("long")) {
    const size_t stride = test::kSanitized ? 41 : 13;
    int files = 0;
    for (auto& entry : std::filesystem::directory_iterator(PSYS_SAMPLES_DIR)) {
        if (entry.path().extension() != ".psys") continue;
        ++files;
        std::string text = test::readFile(entry.path().string());
        for (size_t cut = 0; cut < text.size(); cut += stride) {
            // Cut the file short, and separately drop one character from the middle.
            for (std::string variant : {text.substr(0, cut), text.substr(0, cut) + text.substr(cut + 1)}) {
                auto c = test::check(variant, entry.path().filename().string());
                if (c.ok()) continue;
                checkWording(c.output);
                for (auto& d : c.diags->all()) CHECK(d.range.valid());
            }
        }
    }
    CHECK(files >= 12);
}
