// bs3, the adaptive pair (opt/integrate_adaptive.cpp), on the interpreter: on an eccentric
// orbit, whose steps must shrink near the sun and grow away from it, its error stays within
// the tolerance the object states while its steps change; a tighter tolerance takes
// shorter steps; an update that had to keep a step past its bounds is counted; the step it
// carries is state, zero at creation.
#include <doctest/doctest.h>

#include <array>
#include <cmath>

#include "run.h"

using namespace psys;
using core::Integrator;
using test::kFrame;
using test::Run;

namespace {

// From (1, 0) at the far end of an orbit of eccentricity 0.6 about a unit mass: nearest at
// r = 0.25, four times closer, where it is four times faster; period 2π·0.625^1.5 ≈ 3.10 s.
// Sub-steps of 1/240 s: up to 16 tries a frame (opt/integrate_adaptive.cpp).
std::string eccentric(const std::string& tolerance, const std::string& step = "@step(1/240)") {
    return "@tolerance(" + tolerance + ")\n" + step + R"(
        object planet {
            pos = vec3(1, 0, 0) + integrate(vel);
            vel = vec3(0, sqrt(0.4), 0) + integrate(acc);
            acc = -pos / pow(length(pos), 3);
            point(pos, white, 1);
        }
        spawn planet;)";
}

// The same orbit in double, by rk4 at 1/200 of a frame: each frame's end.
std::vector<std::array<double, 2>> reference(int frames) {
    std::array<double, 4> y = {1, 0, 0, std::sqrt(0.4)};
    auto f = [](const std::array<double, 4>& s) {
        double r3 = std::pow(std::hypot(s[0], s[1]), 3);
        return std::array<double, 4>{s[2], s[3], -s[0] / r3, -s[1] / r3};
    };
    auto plus = [](std::array<double, 4> a, const std::array<double, 4>& b, double h) {
        for (size_t i = 0; i < 4; ++i) a[i] += h * b[i];
        return a;
    };
    const double h = kFrame / 200;
    std::vector<std::array<double, 2>> out;
    for (int frame = 0; frame < frames; ++frame) {
        for (int i = 0; i < 200; ++i) {
            auto k1 = f(y), k2 = f(plus(y, k1, h / 2)), k3 = f(plus(y, k2, h / 2)), k4 = f(plus(y, k3, h));
            for (size_t c = 0; c < 4; ++c) y[c] += h / 6 * (k1[c] + 2 * k2[c] + 2 * k3[c] + k4[c]);
        }
        out.push_back({y[0], y[1]});
    }
    return out;
}

struct Measured {
    double error = 0;                  // the largest distance from the reference, m
    double shortest = INFINITY, longest = 0;  // the step it carried from frame to frame, s
    uint64_t missed = 0;  // updates whose last try kept a step past the bounds
};

Measured measure(const std::string& source, Integrator method, int frames) {
    static const std::vector<std::array<double, 2>> exact = reference(2 * 186);
    REQUIRE(frames <= static_cast<int>(exact.size()));
    Run run(source, {}, true, false, method);
    size_t type = run.type("planet");
    const ir::Object& object = run.system->pool(type).object();
    int slot = -1;
    for (size_t i = 0; i < object.state.size(); ++i)
        if (object.state[i].name == "bs3@step") slot = static_cast<int>(i);
    CHECK((slot >= 0) == (method == Integrator::Bs3));
    Measured m;
    for (int frame = 0; frame < frames; ++frame) {
        run.steps(1, kFrame);
        auto points = run.points("planet");
        REQUIRE(points.size() == 1);
        m.error = std::max(m.error, std::hypot(points[0].position[0] - exact[static_cast<size_t>(frame)][0],
                                               points[0].position[1] - exact[static_cast<size_t>(frame)][1]));
        if (slot < 0) continue;
        const rt::Pool& pool = run.system->pool(type);
        double h = pool.state.get(run.system->backend().memory(), static_cast<size_t>(slot), 0).f[0];
        m.shortest = std::min(m.shortest, h);
        m.longest = std::max(m.longest, h);
    }
    m.missed = run.stats("planet").unstable;
    return m;
}

}  // namespace

TEST_CASE("bs3 keeps an eccentric orbit within its tolerance over two periods while its steps change") {
    const int frames = 2 * 186;  // two periods of 3.10 s
    for (const char* tolerance : {"1e-2, 6.2", "1e-3, 6.2"}) {
        CAPTURE(tolerance);
        double stated = std::atof(tolerance);
        Measured adaptive = measure(eccentric(tolerance), Integrator::Bs3, frames);
        MESSAGE(tolerance << ": error " << adaptive.error << " m, steps " << adaptive.shortest << " to "
                          << adaptive.longest << " s, " << adaptive.missed << " updates past the bounds");
        CHECK(adaptive.error <= stated);
        // Steps of a sub-step (1/240 s) and longer suffice at 1e-2; at 1e-3 they are short
        // near the sun, long away from it.
        if (stated < 1e-2) CHECK(adaptive.longest >= 8 * adaptive.shortest);
    }
}

TEST_CASE("bs3 counts the updates whose last try had to keep a step past its tolerance") {
    // A frame a step: four tries an update, too few near the sun at 1e-3 m.
    Measured m = measure(eccentric("1e-3, 6.2", ""), Integrator::Bs3, 186);
    CHECK(m.missed > 0);
    CHECK(m.missed < 186);
}

TEST_CASE("bs3: a tighter tolerance takes shorter steps, where a fixed step does not notice") {
    const int frames = 186;
    Measured loose = measure(eccentric("1e-2, 3.1"), Integrator::Bs3, frames);
    Measured tight = measure(eccentric("1e-3, 3.1"), Integrator::Bs3, frames);
    CHECK(tight.shortest * 4 <= loose.shortest);
    CHECK(loose.error <= 1e-2);
    CHECK(tight.error <= 1e-3);
    Measured a = measure(eccentric("1e-2, 3.1"), Integrator::Rk2, frames);
    Measured b = measure(eccentric("1e-3, 3.1"), Integrator::Rk2, frames);
    CHECK(a.error == b.error);
}

TEST_CASE("bs3's step is state: zero at creation, then what the error control chose") {
    Run run(eccentric("1e-3"), {}, true, false, Integrator::Bs3);
    size_t type = run.type("planet");
    const ir::Object& object = run.system->pool(type).object();
    REQUIRE(object.state.back().name == "bs3@step");
    CHECK(object.state.back().init == ir::StateInit::Zero);
    run.steps(1, 0);  // the step that creates it
    auto& memory = run.system->backend().memory();
    size_t slot = object.state.size() - 1;
    CHECK(run.system->pool(type).state.get(memory, slot, 0).f[0] == 0);
    run.steps(1, kFrame);
    float h = run.system->pool(type).state.get(memory, slot, 0).f[0];
    CHECK(h > 0);
    CHECK(h <= static_cast<float>(kFrame));  // at most four times the longest it tried: a sub-step of 1/240 s
}
