// The integration methods (docs/language.md, "Integrators"; docs/accuracy.md), on the
// interpreter (exact maths): each method is its own recurrence to the last bit; the
// Runge–Kutta methods converge at their order; `exponential` and `exact` match the
// analytic solutions of their cases; a stiff decay stays bounded where the method can
// keep it so, and is flagged where it cannot; every sample runs under every method, and
// the optimizer changes no bit under any.
#include <doctest/doctest.h>

#include <cfloat>
#include <cmath>
#include <filesystem>
#include <limits>

#include "ir/evaluate.h"
#include "opt/phi.h"
#include "run.h"
#include "tests/run_length.h"

using namespace psys;
using core::Integrator;
using test::kFrame;
using test::Run;

namespace {

constexpr float kEps = std::numeric_limits<float>::epsilon();

std::vector<Integrator> allMethods() {
    std::vector<Integrator> all;
    for (size_t i = 0; i < core::kIntegratorNames.size(); ++i) all.push_back(static_cast<Integrator>(i));
    return all;
}

// The one point an object draws.
rt::RenderPoint only(Run& run, const std::string& type) {
    auto points = run.points(type);
    REQUIRE(points.size() == 1);
    return points[0];
}

// φn(z) as the compiled code computes it (opt/phi.h), in float.
float phiInFloat(int n, float z) {
    ir::Kernel k;
    k.kind = ir::KernelKind::UniformUpdate;
    ir::ValueId v = opt::phi(k, n, k.scalar(z));
    k.yields.push_back({ir::YieldKind::Uniform, 0, 0, v});
    ir::Evaluator e;
    std::vector<ir::Value> out;
    e.run(k, ir::KernelInputs{}, out);
    return out[0].f[0];
}

// φn(z) in double from its definition (φ0 = e^−z, φn = (1/(n−1)! − φn−1)/z), by series
// where the recurrence would cancel.
double phiExact(int n, double z) {
    if (std::fabs(z) < 0.5) {
        double sum = 0, term = 1;
        for (int i = 1; i <= n; ++i) term /= i;
        for (int m = 0; m < 40; ++m) {
            sum += term;
            term *= -z / (m + n + 1);
        }
        return sum;
    }
    double p = std::exp(-z), factorial = 1;
    for (int i = 1; i <= n; ++i) {
        p = (1 / factorial - p) / z;
        factorial *= i;
    }
    return p;
}

// vel = 10 + ∫(−9.8 − 0.5·vel), pos = ∫vel: linear drag with gravity, in one dimension.
const char* kDrag = R"(
    object p {
        vel = 10 + integrate(-9.8 - 0.5 * vel);
        pos = integrate(vel);
        point(vec3(pos, vel, 0), white, 1);
    }
    spawn p;)";

// The drag problem's integrals (vel = 10 + yv, pos = yp) stepped by the float recurrence
// of each method, in the order the lowering builds its sums.
struct DragRecurrence {
    float yv = 0, yp = 0;
    static float fv(float yv) { return -9.8f - 0.5f * (10.0f + yv); }
    static float fp(float yv) { return 10.0f + yv; }

    void step(Integrator m, float dt) {
        float h2 = 0.5f * dt;
        float k1v = fv(yv), k1p = fp(yv);
        switch (m) {
            case Integrator::Euler:
                yp = yp + dt * k1p;
                yv = yv + dt * k1v;
                break;
            case Integrator::Midpoint: {
                float y2 = yv + h2 * k1v;
                yp = yp + dt * fp(y2);
                yv = yv + dt * fv(y2);
                break;
            }
            case Integrator::Rk2: {
                float y2 = yv + dt * k1v;
                yp = yp + h2 * (k1p + fp(y2));
                yv = yv + h2 * (k1v + fv(y2));
                break;
            }
            case Integrator::Rk4: {
                float y2 = yv + h2 * k1v;
                float k2v = fv(y2), k2p = fp(y2);
                float y3 = yv + h2 * k2v;
                float k3v = fv(y3), k3p = fp(y3);
                float y4 = yv + dt * k3v;
                float k4v = fv(y4), k4p = fp(y4);
                float sixth = dt * (1.0f / 6);
                yp = yp + sixth * (((k1p + 2.0f * k2p) + 2.0f * k3p) + k4p);
                yv = yv + sixth * (((k1v + 2.0f * k2v) + 2.0f * k3v) + k4v);
                break;
            }
            case Integrator::Exponential: {
                // vel's linear part: −0.5·vel, solved exactly; pos has none: Euler.
                float phi = phiInFloat(1, 0.5f * dt);
                yp = yp + dt * k1p;
                yv = yv + (dt * phi) * k1v;
                break;
            }
            case Integrator::Leapfrog: {
                // vel reads itself: kicked; pos reads only vel: drifted.
                float half = yv + h2 * k1v, end = yv + dt * k1v;
                yp = yp + dt * fp(half);
                yv = yv + h2 * (k1v + fv(end));
                break;
            }
            default: FAIL("no recurrence written for this method");
        }
    }
};

// The drag problem's exact solution at time t: velocity and position.
std::pair<double, double> dragExact(double t) {
    const double k = 0.5, terminal = -9.8 / k, v0 = 10;
    double v = terminal + (v0 - terminal) * std::exp(-k * t);
    double p = terminal * t + (v0 - terminal) * (1 - std::exp(-k * t)) / k;
    return {v, p};
}

// The undamped spring x'' = −4x from x = 1, v = 0: x = cos 2t.
const char* kSpring = R"(
    object s {
        x = 1 + integrate(v);
        v = integrate(-4 * x);
        point(vec3(x, v, 0), white, 1);
    }
    spawn s;)";

// The largest |x(t) − cos 2t| while stepping the spring to `seconds` in steps of h. (The
// largest, not the last: the error oscillates with the spring, its amplitude grows as
// hᵖ; a single instant may catch it near zero.)
double springError(Integrator m, double h, double seconds) {
    Run run(kSpring, {}, true, false, m);
    int steps = static_cast<int>(std::lround(seconds / h));
    double worst = 0;
    for (int i = 1; i <= steps; ++i) {
        run.steps(1, h);
        worst = std::max(worst, std::fabs(only(run, "s").position[0] - std::cos(2 * i * h)));
    }
    return worst;
}

// v′ = −k·v from 1: object `d`, drawn at (v, 0, 0).
std::string decayAt(int k) {
    return "object d {\n    v = 1 + integrate(-" + std::to_string(k) + " * v);\n"
           "    point(vec3(v, 0, 0), white, 1);\n}\nspawn d;";
}

}  // namespace

TEST_CASE("the φ functions are within a few ulp of their definition, for small and large arguments") {
    for (int n = 0; n <= 3; ++n)
        for (double z : {0.0, 1e-7, 1e-4, 1e-2, 0.3, 1.0, 1.99, 2.01, 5.0, 30.0, 100.0, 1e4, -0.5, -1.5, -3.0, -10.0}) {
            CAPTURE(n);
            CAPTURE(z);
            double exact = phiExact(n, static_cast<float>(z));
            double got = phiInFloat(n, static_cast<float>(z));
            // Relative, but for results below float's normal range (e^−100).
            CHECK(std::fabs(got - exact) <= std::max(8 * kEps * std::fabs(exact), double(FLT_MIN)));
        }
}

TEST_CASE("each Runge–Kutta method, leapfrog and exponential is its own recurrence, bit for bit") {
    for (Integrator m : {Integrator::Euler, Integrator::Midpoint, Integrator::Rk2, Integrator::Rk4,
                         Integrator::Exponential, Integrator::Leapfrog}) {
        CAPTURE(core::integratorName(m));
        Run run(kDrag, {}, true, false, m);
        DragRecurrence r;
        for (int frame = 1; frame <= 120; ++frame) {
            run.steps(1, kFrame);
            r.step(m, static_cast<float>(kFrame));
            rt::RenderPoint p = only(run, "p");
            REQUIRE(p.position[0] == r.yp);
            REQUIRE(p.position[1] == 10.0f + r.yv);
        }
    }
}

TEST_CASE("halving the step divides the error by 2^p: p = 1, 1, 2, 2, 2, 4 (euler, semi_implicit, midpoint, rk2, leapfrog, rk4)") {
    // The steps: where the error is far above float's rounding (rk4's falls to it near
    // ω·h = 0.05, docs/accuracy.md) and the method is in its asymptotic range.
    struct Case {
        Integrator method;
        double order, h, seconds;
    };
    for (Case c : {Case{Integrator::Euler, 1, 0.02, 2}, Case{Integrator::SemiImplicit, 1, 0.02, 2},
                   Case{Integrator::Midpoint, 2, 0.04, 4}, Case{Integrator::Rk2, 2, 0.04, 4},
                   Case{Integrator::Leapfrog, 2, 0.04, 4}, Case{Integrator::Rk4, 4, 0.2, 6}}) {
        CAPTURE(core::integratorName(c.method));
        double e1 = springError(c.method, c.h, c.seconds), e2 = springError(c.method, c.h / 2, c.seconds),
               e3 = springError(c.method, c.h / 4, c.seconds);
        double p1 = std::log2(e1 / e2), p2 = std::log2(e2 / e3);
        CAPTURE(p1);
        CAPTURE(p2);
        CHECK(std::fabs(p1 - c.order) < 0.25);
        CHECK(std::fabs(p2 - c.order) < 0.25);
    }
}

TEST_CASE("exact and exponential match the analytic solutions of their cases within an ulp-scaled bound") {
    // The bound: a few float roundings per step, on the scale of the values, summed over
    // the steps (each step starts from the last one's rounded state).
    auto bound = [](int steps, double scale) { return 4.0 * steps * kEps * std::max(1.0, scale); };
    SUBCASE("linear drag with gravity: exact for velocity and position, exponential for velocity") {
        Run exact(kDrag, {}, true, false, Integrator::Exact), exponential(kDrag, {}, true, false, Integrator::Exponential);
        for (int frame = 1; frame <= 300; ++frame) {
            exact.steps(1, kFrame);
            exponential.steps(1, kFrame);
            auto [v, p] = dragExact(frame * kFrame);
            CHECK(std::fabs(only(exact, "p").position[1] - v) <= bound(frame, 20));
            CHECK(std::fabs(only(exact, "p").position[0] - p) <= bound(frame, 20));
            CHECK(std::fabs(only(exponential, "p").position[1] - v) <= bound(frame, 20));
        }
    }
    SUBCASE("a projectile: the polynomial in age, under exact") {
        Run run(test::kProjectile, {}, true, false, Integrator::Exact);
        for (int frame = 1; frame <= 300; ++frame) {
            run.steps(1, kFrame);
            double t = frame * kFrame;
            CHECK(std::fabs(only(run, "p").position[0] - t) <= bound(frame, 5));
            CHECK(std::fabs(only(run, "p").position[1] - (10 * t - 4.9 * t * t)) <= bound(frame, 75));
        }
    }
    SUBCASE("powers of age and a decay driven by age, under exact") {
        Run run(R"(
            object q {
                cube = integrate(3 * age * age);
                y = integrate(age - 2 * y);
                point(vec3(cube, y, 0), white, 1);
            }
            spawn q;)", {}, true, false, Integrator::Exact);
        for (int frame = 1; frame <= 240; ++frame) {
            run.steps(1, kFrame);
            double t = frame * kFrame;
            CHECK(std::fabs(only(run, "q").position[0] - t * t * t) <= bound(frame, 64));
            CHECK(std::fabs(only(run, "q").position[1] - (t / 2 - 0.25 + std::exp(-2 * t) / 4)) <= bound(frame, 2));
        }
    }
}

TEST_CASE("a stiff decay at k·dt = 100 stays bounded and decays under exponential and exact, and is flagged under euler") {
    std::string stiff = decayAt(6000);
    for (Integrator m : {Integrator::Exponential, Integrator::Exact}) {
        CAPTURE(core::integratorName(m));
        Run run(stiff, {}, true, false, m);
        CHECK(run.diagnostics.find("warning") == std::string::npos);
        for (int frame = 1; frame <= 60; ++frame) {
            run.steps(1, kFrame);
            float v = only(run, "d").position[0];
            CHECK(std::fabs(v) <= 1.0f);
            CHECK(std::fabs(v) <= std::exp(-100.0 * frame) + 4 * kEps);
        }
        CHECK(run.stats("d").unstable == 0);
    }
    Run euler(stiff, {}, true, false, Integrator::Euler);
    CHECK(euler.diagnostics.find("warning: object d: `v` decays at k = 6000/s, and euler is stable only while "
                                 "k·dt < 2") != std::string::npos);
    euler.steps(10, kFrame);
    CHECK(std::fabs(only(euler, "d").position[0]) > 1e15f);  // (1 − 100)^10
    CHECK(euler.stats("d").unstable == 10);
}

TEST_CASE("the stability limit is the method's: k·dt = 2.5 is beyond euler's 2, within rk4's 2.785") {
    std::string decay = decayAt(150);
    Run euler(decay, {}, true, false, Integrator::Euler), rk4(decay, {}, true, false, Integrator::Rk4);
    CHECK(euler.diagnostics.find("warning") != std::string::npos);
    CHECK(rk4.diagnostics.find("warning") == std::string::npos);
    euler.steps(30, kFrame);
    rk4.steps(30, kFrame);
    CHECK(euler.stats("d").unstable == 30);
    CHECK(rk4.stats("d").unstable == 0);
    CHECK(std::fabs(only(euler, "d").position[0]) > 1000);  // |1 − 2.5|^30
    CHECK(std::fabs(only(rk4, "d").position[0]) < 1);
}

TEST_CASE("a decay rate set by the host is checked at run time, every update, and named in the stats") {
    Run run(R"(
        extern rate: float = 1;
        object d {
            v = 1 + integrate(-rate * v);
            point(vec3(v, 0, 0), white, 1);
        }
        spawn d;)");  // the default method
    CHECK(run.diagnostics.find("warning") == std::string::npos);
    run.steps(5, kFrame);
    CHECK(run.stats("d").unstable == 0);
    const float fast[] = {600.0f}, slow[] = {60.0f};
    REQUIRE_FALSE(run.system->setExtern("rate", fast));  // k·dt = 10
    run.steps(7, kFrame);
    CHECK(run.stats("d").unstable == 7);
    REQUIRE_FALSE(run.system->setExtern("rate", slow));  // k·dt = 1
    run.steps(3, kFrame);
    CHECK(run.stats("d").unstable == 7);
}

TEST_CASE("@step sub-steps combine with every method: four sub-steps are four steps of a quarter") {
    for (Integrator m : allMethods()) {
        CAPTURE(core::integratorName(m));
        const char* body = m == Integrator::Exact ? kDrag : kSpring;
        std::string type = m == Integrator::Exact ? "p" : "s";
        Run sub(std::string("@step(1/240)") + body, {}, true, false, m), plain(body, {}, true, false, m);
        for (int frame = 1; frame <= 60; ++frame) {
            sub.steps(1, kFrame);
            plain.steps(4, kFrame / 4);
            rt::RenderPoint a = only(sub, type), b = only(plain, type);
            REQUIRE(test::bitwise(a.position[0], b.position[0]));
            REQUIRE(test::bitwise(a.position[1], b.position[1]));
        }
    }
}

TEST_CASE("exact has no closed form for a coupled system or a non-polynomial derivative: a located error") {
    SourceManager sources;
    DiagnosticEngine diags(sources);
    CompileOptions options;
    options.pipeline.pass.everyObject = Integrator::Exact;
    CHECK_FALSE(compileText("spring.psys", kSpring, sources, diags, options).has_value());
    CHECK(diags.render().find("spring.psys:4:13: error: object s: @integrator(exact) has no closed form for `v`: its "
                              "derivative depends on `x`, whose derivative depends on it") != std::string::npos);
    SourceManager sources2;
    DiagnosticEngine diags2(sources2);
    CHECK_FALSE(compileText("wave.psys", "object w { y = integrate(sin(age)); point(vec3(y), white, 1); }\nspawn w;",
                            sources2, diags2, options)
                    .has_value());
    CHECK(diags2.render().find("wave.psys:1:16: error: object w: @integrator(exact) has no closed form for `y`: its "
                               "derivative applies `sin` to a value that changes within the step") != std::string::npos);
}

TEST_CASE("every sample runs under every method — exact reports those without closed forms") {
    for (Integrator m : allMethods()) {
        for (auto& entry : std::filesystem::directory_iterator(PSYS_SAMPLES_DIR)) {
            if (entry.path().extension() != ".psys") continue;
            std::string name = entry.path().stem().string();
            CAPTURE(core::integratorName(m));
            CAPTURE(name);
            std::string text = test::readFile(entry.path().string());
            bool noClosedForm = name == "bouncing" || name == "campfire" || name == "confetti" || name == "fire" ||
                                name == "swamp";
            if (m == Integrator::Exact && noClosedForm) {
                CHECK_FALSE(test::compiles(text, m));
                continue;
            }
            Run run(text, {}, true, false, m);
            run.steps(test::coverFrames(text, test::kLongRun / 2), kFrame);
            CHECK(run.system->stats().nonFiniteRender == 0);
        }
    }
}

TEST_CASE("the optimizer changes no bit under any method, on every sample") {
    for (Integrator m : allMethods()) {
        CAPTURE(core::integratorName(m));
        CHECK(test::compareWithUnoptimized(false, m, test::kLongRun / 3, test::bitwise, true) > 10000);
    }
}

TEST_CASE("a long-lived orbit drifts no more than its method's error, until float's rounding is the limit") {
    // 100 periods of a circular orbit (628 s) at 60 updates a second. Measured on the
    // interpreter: rk4 4.4e-3 m off the exact position and 9.1e-6 off the energy —
    // rounding, not the method (whose own error at this step is ~1e-7 m): each update
    // rounds a float position of size 1 (6e-8), 37 700 times; midpoint 0.26 m and
    // 3.5e-4, its own phase error. The bounds leave a factor ~2.
    std::string orbit = test::readFile(std::string(PSYS_ACCURACY_DIR) + "/orbit.psys");
    auto run = [&](Integrator m, double& position, double& energy) {
        Run r(orbit, {}, true, false, m);
        const int frames = 37699;  // 100 periods of 2π s
        r.steps(frames, kFrame);
        rt::RenderPoint p = only(r, "planet");
        double t = frames * kFrame;
        position = std::hypot(p.position[0] - std::cos(t), p.position[1] - std::sin(t));
        double v2 = double(p.color[0]) * p.color[0] + double(p.color[1]) * p.color[1];
        energy = std::fabs(v2 / 2 - 1 / std::hypot(double(p.position[0]), double(p.position[1])) + 0.5) / 0.5;
    };
    double position, energy;
    run(Integrator::Rk4, position, energy);
    CHECK(position < 1e-2);
    CHECK(energy < 2e-5);
    run(Integrator::Midpoint, position, energy);
    CHECK(position < 0.5);
    CHECK(energy < 1e-3);
}

// The orbit of bench/accuracy/orbit.psys (period 2π s) in steps of h, for `periods`: the
// largest relative error of the energy v²/2 − 1/r (exactly −½) over the last of them, and
// over the first.
struct EnergyDrift {
    double first = 0, last = 0;
};
EnergyDrift orbitEnergy(Integrator m, int periods, double h = kFrame) {
    std::string orbit = test::readFile(std::string(PSYS_ACCURACY_DIR) + "/orbit.psys");
    Run r(orbit, {}, true, false, m);
    const double period = 2 * M_PI;
    int frames = static_cast<int>(periods * period / h);
    EnergyDrift drift;
    for (int f = 1; f <= frames; ++f) {
        r.steps(1, h);
        double t = f * h;
        bool first = t <= period, last = t >= (periods - 1) * period;
        if (!first && !last) continue;
        rt::RenderPoint p = only(r, "planet");
        double v2 = double(p.color[0]) * p.color[0] + double(p.color[1]) * p.color[1];
        double e = std::fabs(v2 / 2 - 1 / std::hypot(double(p.position[0]), double(p.position[1])) + 0.5) / 0.5;
        (first ? drift.first : drift.last) = std::max(first ? drift.first : drift.last, e);
    }
    return drift;
}

TEST_CASE("semi_implicit cuts the orbit's cycle pos → vel → acc once: symplectic, its energy bounded, unlike euler's") {
    // Evaluated pos, acc, vel (docs/language.md, "Evaluation order"): the position from the
    // last velocity, the acceleration at the new position, the velocity from it — the
    // symplectic Euler step. In source order (pos, vel, acc) both vel and pos would read
    // the last update's values: explicit Euler, whose orbit spirals out.
    EnergyDrift semi = orbitEnergy(Integrator::SemiImplicit, 100), euler = orbitEnergy(Integrator::Euler, 100);
    CAPTURE(semi.first);
    CAPTURE(semi.last);
    CAPTURE(euler.last);
    CHECK(semi.last < 0.05);
    CHECK(semi.last < 1.5 * semi.first + 1e-3);  // no drift: the last period as the first
    CHECK(euler.last > 0.3);
}

TEST_CASE("leapfrog keeps the orbit's energy bounded over 1000 periods: no drift") {
    // At h = 0.1 s (63 steps a period): over the 1000th period the energy error is what it
    // was over the first (measured 2.3e-5 and 3.0e-5, the difference rounding's random
    // walk over 63,000 steps, ~√n·6e-8), where rk2's — the same order, not symplectic —
    // has grown from 2.9e-3 to 0.39.
    EnergyDrift leap = orbitEnergy(Integrator::Leapfrog, 1000, 0.1), rk2 = orbitEnergy(Integrator::Rk2, 1000, 0.1);
    CAPTURE(leap.first);
    CAPTURE(leap.last);
    CAPTURE(rk2.first);
    CAPTURE(rk2.last);
    CHECK(leap.last < 2 * leap.first);
    CHECK(rk2.last > 10 * rk2.first);
    // At 60 updates a second the method's error (3e-6) is near float's: what is left after
    // 377,000 updates is rounding's random walk, ~√n·6e-8.
    EnergyDrift fine = orbitEnergy(Integrator::Leapfrog, 1000);
    CAPTURE(fine.first);
    CAPTURE(fine.last);
    CHECK(fine.first < 1e-5);
    CHECK(fine.last < 1e-4);
}

TEST_CASE("a stage sees derive(e) as of the last update") {
    // Under euler the one stage is the start of the step: it reads derive(age²) as the
    // last update computed it, so x sums the slopes of the updates before: after n
    // updates x = age² one update ago.
    Run run(R"(
        object d {
            x = integrate(derive(age * age));
            point(vec3(x, 0, 0), white, 1);
        }
        spawn d;)", {}, true, false, Integrator::Euler);
    for (int n = 1; n <= 60; ++n) {
        run.steps(1, kFrame);
        double before = (n - 1) * kFrame;
        CHECK(only(run, "d").position[0] == doctest::Approx(before * before).epsilon(1e-4));
    }
}
