// The language server under @tolerance: the chooser runs as `psysc check` runs it (its
// trials on the interpreter), the inlay hint names the method and step it chose, and a
// tolerance it cannot meet is a warning in the editor.
#include <doctest/doctest.h>

#include "lsp_support.h"

using namespace psys;
using namespace psys::lsp;
using namespace psys::lsp::test;
using nlohmann::json;

namespace {

// The labels of the hints on `line` (from 0).
std::vector<std::string> hintsOn(const Analysis& a, const std::string& text, int line) {
    std::vector<std::string> labels;
    for (const json& h : inlayHints(a, 0, static_cast<uint32_t>(text.size())))
        if (h["position"]["line"].get<int>() == line) labels.push_back(h["label"].get<std::string>());
    return labels;
}

// A program's analysis, which must check clean.
Analysis clean(const std::string& path, const std::string& text) {
    Analysis a = analyze(path, text);
    REQUIRE(a.parsed);
    CHECK(a.diagnostics.empty());
    return a;
}

}  // namespace

TEST_CASE("inlay hints say what @tolerance chose, and a tolerance out of reach is a warning") {
    std::string spring = "const w = 6.2831853;\n"
                         "@tolerance(1e-3, 10) object mass {\n"
                         "    x = 1 + integrate(v);\n"
                         "    v = integrate(-w * w * x);\n"
                         "    point(vec3(x, v, 0), white, 1);\n"
                         "}\n"
                         "spawn mass;\n";
    Analysis a = clean("/tmp/tolerance.psys", spring);
    CHECK(hintsOn(a, spring, 1) == std::vector<std::string>{"rk4, a step per update (chosen for @tolerance(0.001))"});

    std::string tight = spring;
    tight.replace(tight.find("@tolerance(1e-3, 10)"), 20, "@integrator(euler) @tolerance(1e-6, 10)");
    Analysis b = analyze("/tmp/tolerance.psys", tight);
    REQUIRE(b.diagnostics.size() == 1);
    CHECK(b.diagnostics[0].severity == Severity::Warning);
    CHECK(b.diagnostics[0].message.find("no integrator and sub-step keeps `mass` within 1e-06 m") != std::string::npos);
}

TEST_CASE("the inlay hint of an object under bs3 says its steps are its own") {
    std::string text = "@integrator(bs3) object drop {\n"
                       "    pos = integrate(vel);\n"
                       "    vel = integrate(vec3(0, -9.8, 0) - 3 * vel);\n"
                       "    point(pos, white, 1);\n"
                       "}\n"
                       "@integrator(bs3) @step(1/240) object fine {\n"
                       "    pos = integrate(vec3(1, 0, 0));\n"
                       "    point(pos, white, 1);\n"
                       "}\n"
                       "spawn drop;\nspawn fine;\n";
    Analysis a = clean("/tmp/bs3.psys", text);
    CHECK(hintsOn(a, text, 0) == std::vector<std::string>{"bs3, adaptive within each update"});
    CHECK(hintsOn(a, text, 5) == std::vector<std::string>{"bs3, adaptive, sub-steps of 1/240 s"});
}

TEST_CASE("the inlay hint of an object under @precision(double) says its state is in double") {
    std::string text = "@precision(double) @integrator(rk4) object ball {\n"
                       "    pos = integrate(vel);\n"
                       "    vel = integrate(vec3(0, -9.8, 0));\n"
                       "    point(pos, white, 1);\n"
                       "}\n"
                       "spawn ball;\n";
    Analysis a = clean("/tmp/double.psys", text);
    CHECK(hintsOn(a, text, 0) == std::vector<std::string>{"rk4, a step per update, state in double"});
}
