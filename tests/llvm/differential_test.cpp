// The LLVM backend against the interpreter: every sample and a program that uses every
// operation, run side by side from the same seed for 600 frames (triggers fired), must
// create, kill and draw the same objects.
//
// In exact maths the values must be the same bit for bit: each operation is compiled to
// the interpreter's float semantics (no fused multiply-add, the same libm functions), so
// a difference is a bug. In fast maths (the default) two things move the last bits:
//   - FMA contraction: a·b + c rounds once instead of twice (≤ 0.5 ulp of the product
//     per fused operation);
//   - libmvec: sin, cos, tan, exp, log and pow on eight objects at a time are within
//     4 ulp of libm's (glibc's documented bound), not equal to them.
// Both are relative errors of about 1e-7 per operation; Euler integration adds them up
// over the steps. Measured, relative to max(1, |value|): at most 3.8e-6 on the samples
// after 600 frames, 1.2e-4 on the every-operation program (tan and pow of values near
// their poles). The tolerance is 5e-4: above both, far below anything visible, and tight
// enough that a wrong operation, lane or column fails.
#define DOCTEST_CONFIG_IMPLEMENT_WITH_MAIN
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "codegen_llvm/llvm_backend.h"
#include "driver/compile.h"
#include "interp/interpreter.h"
#include "rt/system.h"
#include "tests/run_length.h"
#include "tests/differential.h"
#include "tests/system_support.h"

using namespace psys;

namespace {

std::string readFile(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

ir::Module compile(const std::string& text, bool optimize, std::optional<core::Integrator> integrator = {}) {
    return test::compileModule(text, optimize, integrator);
}

using codegen_llvm::MathMode;

constexpr double kTolerance = 5e-4;

// Runs `text` on both backends for `frames` frames.
test::Comparison compareBackends(const std::string& text, int frames, bool optimize, MathMode mode,
                                 std::optional<core::Integrator> integrator = {}) {
    interp::Interpreter interpreter;
    codegen_llvm::LlvmBackend jit(mode);
    rt::System a(compile(text, optimize, integrator), interpreter), b(compile(text, optimize, integrator), jit);
    test::Comparison result = test::compareSystems(a, b, frames);
    if (mode == MathMode::Exact) CHECK(result.differences == 0);
    CHECK(result.worst <= kTolerance);
    return result;
}

}  // namespace

TEST_CASE("every sample draws the same on the LLVM backend as on the interpreter, for 600 frames (200 sanitized)") {
    for (MathMode mode : {MathMode::Exact, MathMode::Fast}) {
        for (auto& entry : std::filesystem::directory_iterator(PSYS_SAMPLES_DIR)) {
            if (entry.path().extension() != ".psys") continue;
            INFO((entry.path().filename().string() + (mode == MathMode::Exact ? " exact" : " fast")));
            CHECK(compareBackends(readFile(entry.path()), test::kLongRun, true, mode).points > 0);
        }
    }
}

TEST_CASE("every operation compiles to the interpreter's result") {
    // Each built-in on values that move with age and with random draws, optimized and not.
    std::string text = readFile(PSYS_EVERY_OPERATION);
    for (MathMode mode : {MathMode::Exact, MathMode::Fast}) {
        INFO(std::string(mode == MathMode::Exact ? "exact" : "fast"));
        for (bool optimize : {false, true}) {
            test::Comparison c = compareBackends(text, 300, optimize, mode);
            CHECK(c.points > 1000);
            MESSAGE("every operation" << std::string(optimize ? ", optimized: " : ": ") << c.points << " points, worst " << c.worst);
        }
    }
}

TEST_CASE("min, max and clamp on NaN and signed zeros: the JIT picks the interpreter's operand") {
    std::string text = readFile(std::string(PSYS_PROGRAMS_DIR) + "/nan_edges.psys");
    for (MathMode mode : {MathMode::Exact, MathMode::Fast})
        for (bool optimize : {false, true}) {
            test::Comparison c = compareBackends(text, 10, optimize, mode);
            CHECK(c.points == 20);
            CHECK(c.differences == 0);
        }
}

TEST_CASE("a kernel of thousands of instructions (cut into blocks, fast code generation) computes the same") {
    std::string sum = "age";
    for (int i = 0; i < 700; ++i) sum += " + sin(age * " + std::to_string(i) + ".5)";
    std::string text = "object o { y = " + sum + "; point(vec3(y, age, 0), white, 1); }\nspawn o;";
    for (MathMode mode : {MathMode::Exact, MathMode::Fast}) {
        test::Comparison c = compareBackends(text, 3, true, mode);
        CHECK(c.points == 3);
    }
}

TEST_CASE("under every integration method every sample draws the same on both backends (exact maths)") {
    for (size_t m = 0; m < core::kIntegratorNames.size(); ++m) {
        auto method = static_cast<core::Integrator>(m);
        for (auto& entry : std::filesystem::directory_iterator(PSYS_SAMPLES_DIR)) {
            if (entry.path().extension() != ".psys") continue;
            std::string text = readFile(entry.path());
            SourceManager sources;
            DiagnosticEngine diags(sources);
            CompileOptions options;
            options.pipeline.pass.everyObject = method;
            if (!compileText("sample.psys", text, sources, diags, options)) continue;  // exact: no closed form
            std::string what = entry.path().filename().string() + " under " + std::string(core::integratorName(method));
            INFO(what);
            CHECK(compareBackends(text, test::kLongRun / 4, true, MathMode::Exact, method).points > 0);
        }
    }
}

TEST_CASE("both backends count the same updates beyond the stability limit") {
    // Objects created every step, each with its own decay rate: some beyond Euler's limit.
    const char* text = R"(
        object d(k: float) {
            v = 1 + integrate(-k * v);
            point(vec3(v, 0, 0), white, 1);
            kill when age > 1;
        }
        object e { emit d(rand() * 240) at 200 per second; }
        spawn e;)";
    interp::Interpreter interpreter;
    codegen_llvm::LlvmBackend jit(MathMode::Fast);
    rt::System a(compile(text, true, core::Integrator::Euler), interpreter),
        b(compile(text, true, core::Integrator::Euler), jit);
    for (int frame = 0; frame < 120; ++frame) {
        REQUIRE_FALSE(a.step(1.0 / 60));
        REQUIRE_FALSE(b.step(1.0 / 60));
    }
    // k·dt > 2 for k > 120: about half the objects, every update.
    CHECK(a.stats().types[0].unstable > 1000);
    CHECK(a.stats().types[0].unstable == b.stats().types[0].unstable);
}
