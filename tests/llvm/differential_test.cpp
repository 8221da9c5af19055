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
// after 600 frames, 9.5e-5 on the every-operation program (tan and pow of values near
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

bool same(const rt::RenderPoint& a, const rt::RenderPoint& b) {
    return a.id == b.id && std::memcmp(&a.position, &b.position, sizeof a.position) == 0 &&
           std::memcmp(&a.color, &b.color, sizeof a.color) == 0 && std::memcmp(&a.size, &b.size, sizeof a.size) == 0;
}

// The largest difference between two points' values, relative to max(1, |value|).
double difference(const rt::RenderPoint& a, const rt::RenderPoint& b) {
    double worst = 0;
    auto compare = [&worst](float x, float y) {
        double d = std::fabs(double(x) - double(y)) / std::max(1.0, std::fabs(double(x)));
        worst = std::max(worst, std::isnan(d) ? (std::isnan(x) && std::isnan(y) ? 0.0 : 1e9) : d);
    };
    for (size_t i = 0; i < 3; ++i) compare(a.position[i], b.position[i]);
    for (size_t i = 0; i < 4; ++i) compare(a.color[i], b.color[i]);
    compare(a.size, b.size);
    return worst;
}

struct Comparison {
    size_t points = 0;
    double worst = 0;
};

// Runs `text` on both backends for `frames` frames.
Comparison compareBackends(const std::string& text, int frames, bool optimize, MathMode mode,
                           std::optional<core::Integrator> integrator = {}) {
    interp::Interpreter interpreter;
    codegen_llvm::LlvmBackend jit(mode);
    rt::System a(compile(text, optimize, integrator), interpreter), b(compile(text, optimize, integrator), jit);
    for (const ir::Trigger& t : a.module().triggers) {
        size_t width = 0;
        for (auto& p : t.params) width += static_cast<size_t>(p.type.width);
        std::vector<float> args(width, 1.5f);
        REQUIRE_FALSE(a.fire(t.name, args));
        REQUIRE_FALSE(b.fire(t.name, args));
    }
    Comparison result;
    size_t differences = 0;
    for (int frame = 0; frame < frames; ++frame) {
        REQUIRE_FALSE(a.step(1.0 / 60));
        REQUIRE_FALSE(b.step(1.0 / 60));
        for (size_t t = 0; t < a.typeCount(); ++t) {
            const auto& pa = a.points(t);
            const auto& pb = b.points(t);
            REQUIRE(pa.size() == pb.size());
            for (size_t i = 0; i < pa.size(); ++i) {
                REQUIRE(pa[i].id == pb[i].id);
                differences += same(pa[i], pb[i]) ? 0 : 1;
                result.worst = std::max(result.worst, difference(pa[i], pb[i]));
            }
            result.points += pa.size();
        }
    }
    if (mode == MathMode::Exact) CHECK(differences == 0);
    CHECK(result.worst <= kTolerance);
    CHECK(a.stats().types.size() == b.stats().types.size());
    for (size_t t = 0; t < a.stats().types.size(); ++t) {
        CHECK(a.stats().types[t].created == b.stats().types[t].created);
        CHECK(a.stats().types[t].killed == b.stats().types[t].killed);
        CHECK(a.stats().types[t].unstable == b.stats().types[t].unstable);
    }
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
    std::string text = R"(
        extern e: vec3 = vec3(0.5, -2, 3);
        object probe(k: float) {
            a = age + k;
            v = vec3(sin(a), cos(a * 1.3), tan(a * 0.2)) * (1 + nrand());
            w = vec3(asin(fract(a) * 0.9), acos(fract(a * 0.7)), atan(a - 2)) + rand3();
            x = atan2(v, w) + pow(abs(w) + 0.1, v) + exp(-a) + log(a + 1) + sqrt(abs(v));
            y = sign(v - w) + floor(v * 3) + ceil(w * 3) + round(v * 2.5) + mod(v * 7, w + 2) + step(w, v);
            z = min(v, w) + max(v, w) + clamp(v, -0.5, 0.5) + mix(v, w, fract(a)) + smoothstep(-1, 1, v);
            g = cross(normalize(v + 0.01), w) + reflect(v, normalize(w + 0.2)) + rotate_x(v, a) + rotate_z(w, -a)
                + rotate_y(e, a) + vec3(dot(v, w), length(v), distance(v, w)) + radians(w) + degrees(v) * 0.01;
            s = integrate(x) + derive(y) + prev(z) + snapshot(g);
            on = v == w || v.xy != w.xy || (a > 1 && a <= 3) || !(a >= 2.5);
            point(s + x + y + z + g, on ? vec4(s, 1) : vec4(x.zyx, age), a % 2);
            kill when age > 8;
        }
        object source { emit probe(rand()) at 30 per second; }
        spawn source;)";
    for (MathMode mode : {MathMode::Exact, MathMode::Fast}) {
        INFO(std::string(mode == MathMode::Exact ? "exact" : "fast"));
        CHECK(compareBackends(text, 300, false, mode).points > 1000);
        CHECK(compareBackends(text, 300, true, mode).points > 1000);
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
