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
#include "host/large_stack.h"
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
                                 std::optional<core::Integrator> integrator = {}, unsigned threads = 0, int fireAt = 0) {
    interp::Interpreter interpreter;
    codegen_llvm::LlvmBackend jit(mode);
    rt::SystemOptions options;
    options.threads = threads;
    rt::System a(compile(text, optimize, integrator), interpreter), b(compile(text, optimize, integrator), jit, options);
    test::Comparison result =
        test::compareSystems(a, b, frames, mode == MathMode::Exact ? INT_MAX : test::closeFrames(a.module()), fireAt);
    if (mode == MathMode::Exact) CHECK(result.differences == 0);
    CHECK(result.worst <= kTolerance);
    return result;
}

}  // namespace

TEST_CASE("every sample draws the same on the LLVM backend as on the interpreter, for 600 frames (200 sanitized)" * doctest::test_suite("long")) {
    for (MathMode mode : {MathMode::Exact, MathMode::Fast}) {
        for (auto& entry : std::filesystem::directory_iterator(PSYS_SAMPLES_DIR)) {
            if (entry.path().extension() != ".psys") continue;
            INFO((entry.path().filename().string() + (mode == MathMode::Exact ? " exact" : " fast")));
            std::string text = readFile(entry.path());
            CHECK(compareBackends(text, test::sweepFrames(text), true, mode).points > 0);
        }
    }
}

TEST_CASE("@precision(double) on the JIT: the interpreter's bits, in exact maths" * doctest::test_suite("long")) {
    // Pair arithmetic (opt/precision_double.cpp) is exact only as written: the JIT must
    // neither contract nor reorder it. Orbits far from the origin, through sqrt, pow and
    // division, comparisons that kill, random starts.
    std::string text = readFile(std::string(PSYS_PROGRAMS_DIR) + "/double_precision.psys");
    test::Comparison c = compareBackends(text, test::kLongRun, true, MathMode::Exact);
    CHECK(c.points > 1000);
    CHECK(c.differences == 0);
}

TEST_CASE("@precision(double) on the JIT holds a projectile to 1e-9 m in exact and in fast maths") {
    // Fast maths contracts a·b + c into one rounding; pair arithmetic must survive it.
    for (core::Integrator method : {core::Integrator::Rk4, core::Integrator::Leapfrog, core::Integrator::Bs3}) {
        for (MathMode mode : {MathMode::Exact, MathMode::Fast}) {
            CAPTURE(core::integratorName(method));
            CAPTURE(mode == MathMode::Exact);
            codegen_llvm::LlvmBackend jit(mode);
            rt::System system(compile("@precision(double) object ball {\n"
                                      "    pos = integrate(vel);\n"
                                      "    vel = vec3(2, 10, 0) + integrate(vec3(0, -9.8, 0));\n"
                                      "    point(pos, white, 1);\n"
                                      "}\nspawn ball;\n",
                                      true, method),
                              jit);
            const ir::Object& object = system.pool(0).object();
            int hi = -1, lo = -1;
            for (size_t i = 0; i < object.state.size(); ++i) {
                if (object.state[i].name == "integrate@pos") hi = static_cast<int>(i);
                if (object.state[i].name == "integrate@pos@lo") lo = static_cast<int>(i);
            }
            REQUIRE(hi >= 0);
            REQUIRE(lo >= 0);
            const double dt = static_cast<float>(1.0 / 240), g = static_cast<float>(-9.8);
            double worst = 0;
            for (int frame = 1; frame <= 480; ++frame) {
                REQUIRE_FALSE(system.step(1.0 / 240).has_value());
                ir::Value h = system.pool(0).state.get(system.backend().memory(), hi, 0);
                ir::Value l = system.pool(0).state.get(system.backend().memory(), lo, 0);
                double t = frame * dt, y = static_cast<double>(h.f[1]) + l.f[1];
                worst = std::max(worst, std::fabs(y - (10 * t + g * t * t / 2)));
            }
            std::string what = std::string(core::integratorName(method)) + (mode == MathMode::Exact ? " exact: " : " fast: ");
            MESSAGE(what, worst, " m");
            CHECK(worst < 1e-9);
        }
    }
}

// The extremes of docs/runtime.md, each past one chunk of rows (8,192) so that threads
// split the work: a pool at capacity under a rate of 10^6 a second, everything killed in
// one frame, a burst of 100k, frozen parents read by their children, a trigger (fired by
// compareSystems).
const char* const kExtremes[] = {
    R"(@capacity(20000) object p { point(vec3(rand(), age, 0), white, 1); kill when age > 0.5 + rand(); }
       object e { emit p at 1000000 per second; }
       spawn e;)",
    R"(object p { point(vec3(rand(), age, 0), white, 1); kill when age > 0.2; }
       object e { emit p count 30000; kill when age > 0.5; }
       spawn e;)",
    R"(object c { point(vec3(rand(), age, 0), white, 1); kill when age > 0.3 + rand(); }
       object b { emit c count 100000; kill when age > 0.1; }
       spawn b;)",
    R"(object grandma {
           emit mom at 20 per second;
           object mom {
               pos = vec3(age, 0, 0);
               point(pos, white, 2);
               emit kid at 40000 per second;
               kill when age > 0.25 + rand() * 0.2;
               object kid {
                   pos = mom.pos + vec3(rand(), age, 0);
                   point(pos, vec4(1, 1, 1, mom.alive ? 1 : 0.5), 1);
                   kill when age > 1 + rand();
               }
           }
       }
       spawn grandma;)",
    R"(object spark(v: vec3) { pos = integrate(v); point(pos, white, 1); kill when age > 0.4; }
       trigger boom(where: vec3) { emit spark(where + nrand3()) count 9000; })",
};

TEST_CASE("the JIT at 1, 2 and 7 threads creates the objects the interpreter creates, in the same rows, with the same ids") {
    std::vector<std::string> programs(std::begin(kExtremes), std::end(kExtremes));
    for (auto& entry : std::filesystem::directory_iterator(PSYS_SAMPLES_DIR))
        if (entry.path().extension() == ".psys") programs.push_back(readFile(entry.path()));
    for (size_t i = 0; i < programs.size(); ++i) {
        INFO("program " << i << ":\n" << programs[i]);
        // The interpreter against 7 threads; 1 and 2 threads against 7 (each pair from the
        // start, side by side: the interpreter, the slow side under the sanitizers, runs once).
        CHECK(compareBackends(programs[i], test::kLongRun / 10, true, MathMode::Exact, {}, 7).points > 0);
        for (unsigned threads : {1u, 2u}) {
            INFO(threads << " threads against 7");
            codegen_llvm::LlvmBackend jitA(MathMode::Exact), jitB(MathMode::Exact);
            rt::SystemOptions few, many;
            few.threads = threads;
            many.threads = 7;
            rt::System a(compile(programs[i], true), jitA, few), b(compile(programs[i], true), jitB, many);
            CHECK(test::compareSystems(a, b, test::kLongRun / 10).differences == 0);
        }
    }
}

TEST_CASE("the step's bookkeeping programs (tests/programs/step_*) on the JIT: the interpreter's rows, ids and bits") {
    // Deaths settled beside bursts, triggers fired mid-run, late kills and nested types:
    // each program once crashed every backend. Exact maths at 1 and 2 threads, fast maths.
    size_t programs = 0;
    for (auto& entry : std::filesystem::directory_iterator(PSYS_PROGRAMS_DIR)) {
        if (!entry.path().filename().string().starts_with("step_")) continue;
        ++programs;
        for (auto [mode, threads] : {std::pair{MathMode::Exact, 1u}, {MathMode::Exact, 2u}, {MathMode::Fast, 2u}}) {
            INFO(entry.path().filename().string() << (mode == MathMode::Exact ? " exact, " : " fast, ") << threads
                                                  << " thread(s)");
            compareBackends(readFile(entry.path()), 120, true, mode, {}, threads, 10);
        }
    }
    CHECK(programs >= 3);
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
    // The front end recurses 700 deep: on a large stack, as psysc and the viewer run it
    // (a sanitized, optimized build's frames outgrow a thread's 8 MB here).
    host::runWithLargeStack([&] {
        for (MathMode mode : {MathMode::Exact, MathMode::Fast}) {
            test::Comparison c = compareBackends(text, 3, true, mode);
            CHECK(c.points == 3);
        }
        return 0;
    });
}

// A test of numbers (each method's kernels the same bits on both backends): under the
// sanitizers each method's lowering and passes run on every sample in "the optimizer
// changes no bit under any method" (tests/unit/integrators_test.cpp), and the JIT's host
// side in the tests above; this sweep (121 s there) runs in the release build.
TEST_CASE("under every integration method every sample draws the same on both backends (exact maths)" *
          doctest::skip(test::kSanitized) * doctest::test_suite("long")) {
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
            CHECK(compareBackends(text, test::coverFrames(text, test::kLongRun / 4), true, MathMode::Exact, method).points > 0);
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
