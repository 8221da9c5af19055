// Running a system on the interpreter in the unit tests: a program as text, compiled with
// the options a test names, and two runs compared side by side.
#pragma once

#include <climits>

#include "tests/run_length.h"

#include <doctest/doctest.h>

#include <cstring>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "driver/compile.h"
#include "interp/interpreter.h"
#include "rt/system.h"
#include "test_support.h"
#include "tests/system_support.h"

namespace psys::test {

// One frame at 60 frames a second: the step the run tests take.
inline constexpr double kFrame = 1.0 / 60;

// A projectile thrown at (1, 10, 0) under gravity, drawn where it is: a program with
// closed forms that several tests run.
constexpr const char* kProjectile = R"(
    object p {
        pos = integrate(vel);
        vel = vec3(1, 10, 0) + integrate(vec3(0, -9.8, 0));
        point(pos, white, 1);
    }
    spawn p;)";

// Rows kept in the memory wherever they can be (SystemOptions::Rows::InMemory), as on a
// GPU: no drawing as the step goes (a type drawn so keeps its rows on the host).
inline rt::SystemOptions rowsInMemory() {
    rt::SystemOptions options;
    options.rows = rt::SystemOptions::Rows::InMemory;
    options.drawInStep = false;
    return options;
}

struct Run {
    interp::Interpreter backend;
    std::unique_ptr<rt::System> system;
    std::string diagnostics;  // what compiling printed (warnings)

    explicit Run(const std::string& source, rt::SystemOptions options = {}, bool optimize = true, bool relaxed = false,
                 std::optional<core::Integrator> integrator = {}) {
        system = std::make_unique<rt::System>(compileModule(source, optimize, integrator, relaxed, &diagnostics), backend,
                                              options);
    }

    void steps(int n, double dt) {
        for (int i = 0; i < n; ++i) REQUIRE_FALSE(system->step(dt).has_value());
    }
    size_t type(const std::string& name) const {
        int index = system->typeIndex(name);
        REQUIRE_MESSAGE(index >= 0, "no type " << name << " (a nested type's name is its path: a.b)");
        return static_cast<size_t>(index);
    }
    std::vector<rt::RenderPoint> points(const std::string& name) { return system->points(type(name)); }
    rt::TypeStats stats(const std::string& name) const { return system->stats().types[type(name)]; }
};

// The interpreter, shown each rows launch before it runs it: a test's look at what the
// run-time asks of a backend.
struct WatchedInterpreter : rt::Backend {
    interp::Interpreter inner;
    std::function<void(const rt::RowsLaunch&)> watch;
    explicit WatchedInterpreter(std::function<void(const rt::RowsLaunch&)> w) : watch(std::move(w)) {}
    std::string name() const override { return "watched"; }
    rt::Memory& memory() override { return inner.memory(); }
    rt::RowsResult run(const rt::RowsLaunch& l) override {
        watch(l);
        return inner.run(l);
    }
    void run(const rt::ChildrenLaunch& l) override { inner.run(l); }
};

// Every sample, the programs of tests/programs, and cells that emit their own type at
// capacity (created after their type's update, some dying in their first update).
inline std::vector<std::string> samplesAndPrograms() {
    std::vector<std::string> all;
    for (const char* dir : {PSYS_SAMPLES_DIR, PSYS_PROGRAMS_DIR})
        for (auto& entry : std::filesystem::directory_iterator(dir))
            if (entry.path().extension() == ".psys") all.push_back(test::readFile(entry.path().string()));
    all.push_back(R"(
        @capacity(300) object cell {
            point(vec3(rand(), rand(), 0) * age, vec4(age, 1, 0, 1), 1 / (age - 0.25));
            emit cell at 90 per second;
            kill when age > 0.5 + rand();
        }
        spawn cell;)");
    return all;
}

inline bool bitwise(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Runs two systems side by side for `frames` frames, firing every trigger once, and
// compares what is drawn: the same objects, and values compared by `close`. Returns the
// number of points compared.
// Values over the first `closeFrames` frames only (test::closeFrames), what is alive over all.
inline size_t compareRuns(Run& a, Run& b, int frames, const std::function<bool(float, float)>& close,
                          int closeFrames = INT_MAX) {
    for (const ir::Trigger& t : a.system->module().triggers) {
        size_t width = 0;
        for (auto& p : t.params) width += static_cast<size_t>(p.type.width);
        std::vector<float> args(width, 1.5f);
        REQUIRE_FALSE(a.system->fire(t.name, args));
        REQUIRE_FALSE(b.system->fire(t.name, args));
    }
    size_t points = 0, differences = 0;
    for (int frame = 0; frame < frames; ++frame) {
        a.steps(1, 1.0 / 60);
        b.steps(1, 1.0 / 60);
        for (size_t t = 0; t < a.system->typeCount(); ++t) {
            const auto& pa = a.system->points(t);
            const auto& pb = b.system->points(t);
            REQUIRE(pa.size() == pb.size());
            for (size_t i = 0; i < pa.size(); ++i) {
                if (frame >= closeFrames) {
                    CHECK(pa[i].id == pb[i].id);
                    continue;
                }
                ++points;
                bool same = pa[i].id == pb[i].id && close(pa[i].size, pb[i].size);
                for (size_t c = 0; c < 3; ++c) same &= close(pa[i].position[c], pb[i].position[c]);
                for (size_t c = 0; c < 4; ++c) same &= close(pa[i].color[c], pb[i].color[c]);
                differences += same ? 0 : 1;
            }
        }
    }
    CHECK(differences == 0);
    for (size_t t = 0; t < a.system->typeCount(); ++t) {
        CHECK(a.system->stats().types[t].created == b.system->stats().types[t].created);
        CHECK(a.system->stats().types[t].killed == b.system->stats().types[t].killed);
        CHECK(a.system->stats().types[t].dropped == b.system->stats().types[t].dropped);
        CHECK(a.system->stats().types[t].unstable == b.system->stats().types[t].unstable);
    }
    return points;
}

// Whether a sample has a closed form for every integral (what `exact` needs).
inline bool compiles(const std::string& text, std::optional<core::Integrator> integrator) {
    SourceManager sources;
    DiagnosticEngine diags(sources);
    CompileOptions compile;
    compile.pipeline.pass.everyObject = integrator;
    return compileText("test.psys", text, sources, diags, compile).has_value();
}

// Every sample (that compiles under `integrator`) for `frames` frames without the
// optimizer against with it; `cover`: only as many of them as test::coverFrames says
// every type needs (a sweep over methods; any sweep under the sanitizers: sweepFrames).
inline size_t compareWithUnoptimized(bool relaxed, std::optional<core::Integrator> integrator, int frames,
                                     const std::function<bool(float, float)>& close, bool cover = false) {
    size_t points = 0;
    for (auto& entry : std::filesystem::directory_iterator(PSYS_SAMPLES_DIR)) {
        if (entry.path().extension() != ".psys") continue;
        INFO(entry.path().filename().string());
        std::string text = readFile(entry.path().string());
        if (integrator && !compiles(text, integrator)) continue;
        Run plain(text, {}, false, false, integrator), optimized(text, {}, true, relaxed, integrator);
        // (relaxed maths rounds otherwise: a crowd is compared over its first frames)
        points += compareRuns(plain, optimized, cover ? coverFrames(text, frames) : frames, close,
                              relaxed ? test::closeFrames(plain.system->module()) : INT_MAX);
    }
    return points;
}

}  // namespace psys::test
