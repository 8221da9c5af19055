// What the GPU tests share: the GLSL backend (with or without its host side), a program on
// the interpreter and on the GPU stepped together, and the tolerances (gpu_test.cpp says
// why they are what they are).
#pragma once

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <vector>

#include "gpu/gl_debug.h"
#include "gpu/glsl_backend.h"
#include "interp/interpreter.h"
#include "tests/differential.h"
#include "tests/run_length.h"
#include "tests/system_support.h"

namespace psys::test {

inline constexpr double kSamplesTolerance = 1e-4, kEveryOperationTolerance = 1e-2;

// Where the samples and test programs are: the source tree's (compiled in), or where the
// environment says (a GPU bundle carries them beside its binaries: scripts/gpu-bundle.sh).
inline std::string dataPath(const char* variable, const char* compiledIn) {
    const char* v = std::getenv(variable);
    return v && *v ? v : compiledIn;
}
inline std::string samplesDir() { return dataPath("PSYS_SAMPLES_DIR", PSYS_SAMPLES_DIR); }
inline std::string programsDir() { return dataPath("PSYS_PROGRAMS_DIR", PSYS_PROGRAMS_DIR); }
inline std::string sample(const std::string& name) { return samplesDir() + "/" + name + ".psys"; }

// Whether the suite runs on a second GL (strict mode or zink: main.cpp sets PSYS_GL).
inline bool onSecondGl() {
    const char* gl = std::getenv("PSYS_GL");
    return gl && *gl;
}

// The samples a sweep runs: every one on the machine's GL. On a second GL, which looks for
// a missing barrier or work done out of order, "every sample draws the same" sweeps them
// all (each sample's shaders compiled there, each step's order); the other sweeps (the
// box, the host side) add their own code to it, which these four run there: bursts on
// death and a trigger (fireworks), a crowd's folds (boids), trails (wand), a plain
// emitter (fountain).
inline std::vector<std::filesystem::path> sweptSamples() {
    std::vector<std::filesystem::path> all;
    for (auto& entry : std::filesystem::directory_iterator(samplesDir()))
        if (entry.path().extension() == ".psys") all.push_back(entry.path());
    std::sort(all.begin(), all.end());
    if (!onSecondGl()) return all;
    std::vector<std::filesystem::path> few;
    for (const char* name : {"boids", "fireworks", "fountain", "wand"}) few.push_back(sample(name));
    return few;
}

inline std::string readFile(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

// Every GPU test runs in a debug context (KHR_debug): a GL error or undefined behaviour
// reported while a backend lives fails the test that made it, when the backend goes.
struct GlMessagesChecked {
    uint64_t before = gpu::glErrorMessages();
    void operator()(gpu::GlslBackend* b) const {
        delete b;
        CHECK_MESSAGE(gpu::glErrorMessages() == before, "the GL reported: " << gpu::lastGlErrorMessage());
    }
};
using GpuBackend = std::unique_ptr<gpu::GlslBackend, GlMessagesChecked>;

// hostSide: small pools' launches on the host, as psysc and the viewer run them
// (GlslBackend::setHostSide); without it every launch runs on the GPU, which the
// differential tests must cover.
inline GpuBackend gpuBackend(bool hostSide = false) {
    gpu::requestDebugOutput(true);
    std::string error;
    auto created = gpu::GlslBackend::create(error);
    INFO(error);
    REQUIRE(created);
    GpuBackend b(created.release());
    if (hostSide) b->setHostSide(std::make_unique<interp::Interpreter>(b->memory()));
    return b;
}

// A program on the interpreter and on the GPU, stepped together.
struct Pair {
    interp::Interpreter interpreter;
    GpuBackend gpu;
    std::unique_ptr<rt::System> cpu, gl;

    explicit Pair(const std::string& text, bool optimize = true, bool hostSide = false, rt::SystemOptions options = {})
        : gpu(gpuBackend(hostSide)) {
        cpu = std::make_unique<rt::System>(test::compileModule(text, optimize), interpreter);
        gl = std::make_unique<rt::System>(test::compileModule(text, optimize), *gpu, options);
    }
    void steps(int n, double dt) {
        for (int i = 0; i < n; ++i) {
            REQUIRE_FALSE(cpu->step(dt));
            REQUIRE_FALSE(gl->step(dt));
        }
    }
    void setExtern(const char* name, std::span<const float> v) {
        REQUIRE_FALSE(cpu->setExtern(name, v));
        REQUIRE_FALSE(gl->setExtern(name, v));
    }
    void fire(const char* name) {
        REQUIRE_FALSE(cpu->fire(name, {}));
        REQUIRE_FALSE(gl->fire(name, {}));
    }
    rt::TypeStats stats(const char* type) const { return gl->stats().types.at(static_cast<size_t>(gl->typeIndex(type))); }
    // What both draw now, and every count: the same.
    double compare() {
        double worst = 0;
        // What is drawn before the GPU's late kills are taken (at the next step) leaves them
        // out; the counts are exact once they are.
        for (size_t t = 0; t < cpu->typeCount(); ++t) {
            auto a = cpu->points(t), b = gl->points(t);
            INFO("type " << cpu->module().objects[t].name << ", step " << cpu->stepCount());
            REQUIRE(a.size() == b.size());
            for (size_t i = 0; i < a.size(); ++i) {
                REQUIRE(a[i].id == b[i].id);
                worst = std::max(worst, test::pointDifference(a[i], b[i]));
            }
        }
        gl->finish();
        cpu->finish();
        CHECK(test::sameRows(*cpu, *gl));  // the same objects in the same rows
        for (size_t t = 0; t < cpu->typeCount(); ++t) {
            const rt::TypeStats sa = cpu->stats().types[t];
            const rt::TypeStats sb = gl->stats().types[t];
            CHECK(sa.live == sb.live);
            CHECK(sa.created == sb.created);
            CHECK(sa.killed == sb.killed);
            CHECK(sa.dropped == sb.dropped);
            CHECK(sa.frozen == sb.frozen);
        }
        CHECK(cpu->stats().nonFiniteRender == gl->stats().nonFiniteRender);
        CHECK(cpu->stats().nonFiniteExterns == gl->stats().nonFiniteExterns);
        CHECK(cpu->stats().invalidEmissions == gl->stats().invalidEmissions);
        CHECK(worst <= kSamplesTolerance);
        return worst;
    }
};

inline test::Comparison compareProgram(const std::string& text, int frames, bool optimize, double tolerance,
                                       bool hostSide = false, int fireAt = 0) {
    interp::Interpreter interpreter;
    auto gpu = gpuBackend(hostSide);
    rt::System a(test::compileModule(text, optimize), interpreter), b(test::compileModule(text, optimize), *gpu);
    test::Comparison result = test::compareSystems(a, b, frames, test::closeFrames(a.module()), fireAt);
    CHECK(result.worst <= tolerance);
    return result;
}


}  // namespace psys::test
