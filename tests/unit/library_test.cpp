// The standard library (library/std, docs/library.md): each module against what its
// names promise — uniform shapes by a Kolmogorov–Smirnov test on many draws, forces and
// collisions against closed forms, colours against known values — on the interpreter
// (the backends are compared with it on the samples that import the library).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include <fmt/format.h>

#include "run.h"

using namespace psys;
using test::Run;

namespace {

using Vec = std::array<float, 3>;

// `n` points drawn from `shape` (an expression of std/shapes.psys), each kept by an object.
std::vector<Vec> draws(const std::string& shape, int n = 20000) {
    Run run(fmt::format(R"(
        import "std/shapes.psys";
        object p(q: vec3) {{ point(snapshot(q), white, 1); }}
        object e {{ emit p({}) count {}; kill; }}
        spawn e;)", shape, n));
    run.steps(1, 1.0 / 60);
    std::vector<Vec> out;
    for (const auto& p : run.points("p")) out.push_back(p.position);
    REQUIRE(out.size() == static_cast<size_t>(n));
    return out;
}

// The Kolmogorov–Smirnov distance between the values' distribution and U(0, 1).
double ksUniform(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    double d = 0, n = static_cast<double>(v.size());
    for (size_t i = 0; i < v.size(); ++i)
        d = std::max({d, std::abs((i + 1) / n - v[i]), std::abs(v[i] - i / n)});
    return d;
}

// Uniform at the 0.1 % level: the critical distance is 1.95 / √n.
void checkUniform(const std::vector<double>& v, const char* what) {
    double d = ksUniform(v), critical = 1.95 / std::sqrt(static_cast<double>(v.size()));
    INFO(what << ": KS distance " << d << ", critical " << critical);
    CHECK(d < critical);
}

double len(const Vec& p) { return std::sqrt(double(p[0]) * p[0] + double(p[1]) * p[1] + double(p[2]) * p[2]); }
double angle01(double y, double x) { return (std::atan2(y, x) + M_PI) / (2 * M_PI); }

template <typename F>
std::vector<double> map(const std::vector<Vec>& ps, F f) {
    std::vector<double> out;
    for (const Vec& p : ps) out.push_back(f(p));
    return out;
}

}  // namespace

TEST_CASE("std/shapes: a ball, a sphere and a direction are uniform") {
    auto ball = draws("in_sphere(2)");
    checkUniform(map(ball, [](const Vec& p) { return std::pow(len(p) / 2, 3); }), "the ball's volume inside the radius");
    checkUniform(map(ball, [](const Vec& p) { return (p[2] / len(p) + 1) / 2; }), "the ball's height along z");
    checkUniform(map(ball, [](const Vec& p) { return angle01(p[1], p[0]); }), "the ball's turn about z");
    auto sphere = draws("on_sphere(3)");
    for (const Vec& p : sphere) CHECK(len(p) == doctest::Approx(3).epsilon(1e-5));
    checkUniform(map(sphere, [](const Vec& p) { return (p[1] / 3 + 1) / 2; }), "the sphere's height along y");
    checkUniform(map(sphere, [](const Vec& p) { return angle01(p[0], p[2]); }), "the sphere's turn about y");
}

TEST_CASE("std/shapes: a line, a box, a disc, a ring and a circle are uniform") {
    auto line = draws("on_line(vec3(1, 2, 3), vec3(3, 2, 3))");
    checkUniform(map(line, [](const Vec& p) { return (p[0] - 1) / 2; }), "along the line");
    auto box = draws("in_box(vec3(-1, 0, 2), vec3(1, 4, 3))");
    checkUniform(map(box, [](const Vec& p) { return (p[0] + 1) / 2; }), "the box's x");
    checkUniform(map(box, [](const Vec& p) { return p[1] / 4; }), "the box's y");
    checkUniform(map(box, [](const Vec& p) { return p[2] - 2; }), "the box's z");
    auto disc = draws("in_disc(2)");
    for (const Vec& p : disc) CHECK(p[1] == 0.0f);
    checkUniform(map(disc, [](const Vec& p) { return (p[0] * p[0] + p[2] * p[2]) / 4; }), "the disc's area inside the radius");
    checkUniform(map(disc, [](const Vec& p) { return angle01(p[2], p[0]); }), "the disc's turn");
    auto ring = draws("in_ring(1, 2)");
    checkUniform(map(ring, [](const Vec& p) { return (p[0] * p[0] + p[2] * p[2] - 1) / 3; }), "the ring's area");
    auto circle = draws("on_circle(1.5)");
    for (const Vec& p : circle) CHECK(std::hypot(p[0], p[2]) == doctest::Approx(1.5).epsilon(1e-5));
    checkUniform(map(circle, [](const Vec& p) { return angle01(p[2], p[0]); }), "the circle's turn");
}

TEST_CASE("std/shapes: a cone's directions stay within its angle, uniform over its cap, about any axis") {
    for (std::string axis : {"vec3(0, 1, 0)", "vec3(1, 1, -2)", "vec3(0, 0, -1)"}) {
        INFO(axis);
        const double angle = 0.4;
        auto cone = draws("in_cone(" + axis + ", 0.4)");
        Vec a = axis == "vec3(0, 1, 0)" ? Vec{0, 1, 0} : axis == "vec3(0, 0, -1)" ? Vec{0, 0, -1} : Vec{1, 1, -2};
        double an = len(a);
        auto cosine = [&](const Vec& p) { return (p[0] * a[0] + p[1] * a[1] + p[2] * a[2]) / (len(p) * an); };
        for (const Vec& p : cone) CHECK(len(p) == doctest::Approx(1).epsilon(1e-5));
        double widest = 0;
        for (const Vec& p : cone) widest = std::max(widest, std::acos(std::min(cosine(p), 1.0)));
        CHECK(widest <= angle + 1e-3);
        CHECK(widest >= angle - 0.01);
        checkUniform(map(cone, [&](const Vec& p) { return (1 - cosine(p)) / (1 - std::cos(angle)); }), "the cap's area");
    }
}

TEST_CASE("std/shapes: a torus is uniform by volume: more of it on its outer side") {
    const double major = 2, minor = 1;
    auto torus = draws("in_torus(2, 1)");
    size_t outer = 0;
    std::vector<double> tube;  // (ρ / minor)², uniform: the tube's cross-section is uniform
    for (const Vec& p : torus) {
        double out = std::hypot(p[0], p[2]);
        double rho2 = (out - major) * (out - major) + double(p[1]) * p[1];
        CHECK(rho2 <= minor * minor * (1 + 1e-4));
        tube.push_back(rho2 / (minor * minor));
        outer += out > major;
    }
    checkUniform(tube, "the tube's cross-section");
    // The outer half's share of the volume: 1/2 + 2·minor / (3π·major).
    double share = static_cast<double>(outer) / torus.size(), expected = 0.5 + 2 * minor / (3 * M_PI * major);
    MESSAGE("outer share " << share << ", by volume " << expected);
    CHECK(std::abs(share - expected) < 0.012);
    checkUniform(map(torus, [](const Vec& p) { return angle01(p[2], p[0]); }), "the turn about y");
}

namespace {

// The value of a vec4 expression of the library (each module imported), as drawn.
std::array<float, 4> value(const std::string& expr) {
    Run run(R"(
        import "std/color.psys"; import "std/forces.psys"; import "std/collide.psys"; import "std/shapes.psys";
        object o { point(origin, )" + expr + R"(, 1); }
        spawn o;)");
    run.steps(1, 1.0 / 60);
    auto points = run.points("o");
    REQUIRE(points.size() == 1);
    return points[0].color;
}

void near(const std::array<float, 4>& got, std::array<float, 4> want, double tolerance = 1e-5) {
    for (size_t c = 0; c < 4; ++c) {
        INFO("component " << c << ": " << got[c] << " for " << want[c]);
        CHECK(std::abs(got[c] - want[c]) <= tolerance);
    }
}

}  // namespace

TEST_CASE("std/color: ramps and curves go through their stops, linear between, held outside") {
    const std::string r = "ramp4({}, 0, white, 0.2, yellow, 0.6, red, 1, transparent)";
    near(value(fmt::format(fmt::runtime(r), "-1")), {1, 1, 1, 1});
    near(value(fmt::format(fmt::runtime(r), "0.2")), {1, 1, 0, 1});
    near(value(fmt::format(fmt::runtime(r), "0.4")), {1, 0.5f, 0, 1});
    near(value(fmt::format(fmt::runtime(r), "0.8")), {0.5f, 0, 0, 0.5f});
    near(value(fmt::format(fmt::runtime(r), "3")), {0, 0, 0, 0});
    near(value("ramp8(0.65, 0, red, 0.1, green, 0.2, blue, 0.3, white, 0.4, black, 0.5, red, 0.6, green, 0.7, blue)"),
         {0, 0.5f, 0.5f, 1});
    near(value("vec4(curve3(0.75, 0, 1, 0.5, 3, 1, 0), fade_in_out(0.5, 0.1, 0.1), fade_in_out(0, 0.1, 0.1), 0)"),
         {1.5f, 1, 0, 0});
}

TEST_CASE("std/color: hue, saturation and value, sRGB and linear light, there and back") {
    near(value("vec4(hsv(0, 1, 1), 1)"), {1, 0, 0, 1});
    near(value("vec4(hsv(1 / 3, 1, 1), 1)"), {0, 1, 0, 1});
    near(value("vec4(hsv(2 / 3, 1, 0.5), 1)"), {0, 0, 0.5f, 1});
    near(value("vec4(hsv(0.9, 0, 0.3), 1)"), {0.3f, 0.3f, 0.3f, 1});
    for (const char* hsv : {"0.1, 0.5, 0.8", "0.45, 1, 0.3", "0.8, 0.2, 1"}) {
        INFO(hsv);
        auto back = value(fmt::format("vec4(to_hsv(hsv({})), 1)", hsv));
        auto want = value(fmt::format("vec4({}, 1)", hsv));
        near(back, want, 1e-5);
    }
    near(value("vec4(srgb_to_linear(vec3(0.5, 0.02, 1)), 1)"), {0.21404114f, 0.02f / 12.92f, 1, 1});
    near(value("vec4(linear_to_srgb(srgb_to_linear(vec3(0.5, 0.02, 0.9))), 1)"), {0.5f, 0.02f, 0.9f, 1});
}

TEST_CASE("std/color: a black body goes from orange through white to blue as it heats") {
    auto candle = value("vec4(blackbody(1800), 1)"), day = value("vec4(blackbody(6500), 1)"),
         sky = value("vec4(blackbody(10000), 1)");
    CHECK(candle[0] == doctest::Approx(1));
    CHECK(candle[1] < 0.6f);
    CHECK(candle[2] < 0.2f);
    for (int c = 0; c < 3; ++c) CHECK(day[static_cast<size_t>(c)] > 0.9f);
    CHECK(sky[2] == doctest::Approx(1));
    CHECK(sky[0] < 0.85f);
    float lastRatio = 0;
    for (int k = 2500; k <= 20000; k += 700) {  // bluer with every step up (blue is 0 below about 1900 K)
        auto c = value(fmt::format("vec4(blackbody({}), 1)", k));
        INFO(k << " K: " << c[0] << " " << c[1] << " " << c[2]);
        CHECK(c[2] / c[0] > lastRatio);
        lastRatio = c[2] / c[0];
    }
}

TEST_CASE("std/forces: drag_step is stable for any k·dt and reaches the terminal velocity a / k") {
    for (double dt : {1.0 / 60, 1.0 / 10}) {
        INFO("dt " << dt);
        // k·dt from 0.05 to 50: an explicit step diverges past 2.
        for (double k : {3.0, 30.0, 500.0}) {
            INFO("k " << k);
            Run run(fmt::format(R"(
                import "std/forces.psys";
                object o {{ vel = vec3(0, 5, 0) -> drag_step(prev(vel), earth_gravity, {}, dt); point(origin, vec4(vel, 1), 1); }}
                spawn o;)", k));
            run.steps(static_cast<int>(4 / dt), dt);
            float v = run.points("o")[0].color[1];
            double terminal = -9.80665 / k, t = run.system->time();
            double exact = terminal + (5 - terminal) * std::exp(-k * t);  // (created at 0, one update a step)
            CHECK(v == doctest::Approx(exact).epsilon(1e-4));
            CHECK(std::isfinite(v));
        }
    }
}

TEST_CASE("std/forces: quadratic drag gives the terminal speed √(g / k), and an orbit the period 2π·√(r³ / strength)") {
    Run fall(R"(
        import "std/forces.psys";
        object o { vel = integrate(earth_gravity + quadratic_drag(vel, 0.2)); point(origin, vec4(vel, 1), 1); }
        spawn o;)");
    fall.steps(600, 1.0 / 60);
    CHECK(-fall.points("o")[0].color[1] == doctest::Approx(std::sqrt(9.80665 / 0.2)).epsilon(1e-3));
    // r = 2, strength 8: speed 2, period 2π.
    Run orbit(R"(
        import "std/forces.psys";
        @integrator(rk4)
        object o {
            pos = vec3(2, 0, 0) + integrate(vel);
            vel = vec3(0, 0, orbit_speed(2, 8)) + integrate(attract(pos, origin, 8, 0));
            point(pos, white, 1);
        }
        spawn o;)");
    const int steps = 480;  // one period, 2π s, in steps of 2π / 480
    orbit.steps(steps, 2 * M_PI / steps);
    auto p = orbit.points("o")[0].position;
    MESSAGE("after one period: " << p[0] << ", " << p[1] << ", " << p[2]);
    CHECK(p[0] == doctest::Approx(2).epsilon(1e-4));
    CHECK(std::abs(p[2]) < 1e-3);
}

TEST_CASE("std/forces: a vortex turns about its axis, an attraction points at its target and softens") {
    // The swirl is across the axis and the offset: no part along either.
    near(value("vec4(dot(vortex(vec3(1, 2, 0.5), vec3(0, 1, 0), vec3(0, 1, 0), 2, 0.1), vec3(1, 0, 0.5)), "
               "dot(vortex(vec3(1, 2, 0.5), vec3(0, 1, 0), vec3(0, 1, 0), 2, 0.1), vec3(0, 1, 0)), 0, 0)"),
         {0, 0, 0, 0});
    near(value("vec4(attract(vec3(2, 0, 0), origin, 8, 0), 0)"), {-2, 0, 0, 0});
    near(value("vec4(repel(vec3(2, 0, 0), origin, 8, 0), 0)"), {2, 0, 0, 0});
    near(value("vec4(attract(vec3(0, 0, 0), origin, 8, 0.5), length(attract(vec3(0.01, 0, 0), origin, 1, 1)))"),
         {0, 0, 0, 0.01f}, 1e-4);
    near(value("vec4(spring(vec3(1, 0, 0), vec3(0, 2, 0), origin, 3, 0.5), 0)"), {-3, -1, 0, 0});
}

TEST_CASE("std/collide: a dropped ball's apex after each bounce is restitution² × the one before, whatever the step") {
    // Dropped from rest at 5 m: after k bounces its apex is 5·e^(2k). Its apex is known in
    // every step from its height and speed (y + v²/2g: flight under gravity alone), so no
    // sampling of the top is needed.
    for (double dt : {1.0 / 240, 1.0 / 60, 1.0 / 17}) {
        INFO("dt " << dt);
        Run run(R"(
            import "std/collide.psys"; import "std/forces.psys";
            object b {
                (pos, vel) = (vec3(0, 5, 0), vec3(0.5, 0, 0)) -> bounce_ground(prev(pos), prev(vel), earth_gravity, dt, 0.8, 0);
                point(pos, vec4(vel, 1), 1);
            }
            spawn b;)");
        int bounces = 0;
        float lastVy = 0, lowest = 1;
        for (int step = 0; step < static_cast<int>(3 / dt); ++step) {
            run.steps(1, dt);
            auto p = run.points("b")[0];
            float y = p.position[1], vy = p.color[1];
            lowest = std::min(lowest, y);
            bounces += lastVy < 0 && vy > 0;
            lastVy = vy;
            double apex = y + double(vy) * vy / (2 * 9.80665);
            CHECK(apex == doctest::Approx(5 * std::pow(0.64, bounces)).epsilon(2e-4));
        }
        CHECK(bounces >= 2);
        CHECK(lowest >= 0.0f);
    }
}

TEST_CASE("std/collide: nothing passes a plane, leaves a box or enters a sphere, however fast") {
    Run run(R"(
        import "std/collide.psys"; import "std/forces.psys";
        object b(ivel: vec3) {
            (pos, vel) = (vec3(0, 1, 0), ivel) -> bounce_plane(prev(pos), prev(vel), earth_gravity, dt,
                                                               vec3(0, 0.5, 0), normalize(vec3(0.3, 1, 0)), 0.6, 0.2);
            point(pos, white, 1);
        }
        object x(ivel: vec3) {
            (pos, vel) = (vec3(0, 1, 0), ivel) -> bounce_box(prev(pos), prev(vel), earth_gravity, dt,
                                                             vec3(-1, 0, -1), vec3(1, 2, 1), 0.9, 0.1);
            point(pos, white, 1);
        }
        object s(ivel: vec3) {
            (pos, vel) = (vec3(0, 4, 0), ivel) -> bounce_sphere(prev(pos), prev(vel), earth_gravity, dt,
                                                                vec3(0, 1, 0), 2, 0.7, 0);
            point(pos, white, 1);
        }
        object e { emit b(nrand3() * 30) count 200; emit x(nrand3() * 40) count 200; emit s(nrand3() * 5) count 200; kill; }
        spawn e;)");
    for (int step = 0; step < 300; ++step) {
        run.steps(1, 1.0 / 60);
        for (const auto& p : run.points("b")) {
            double side = (0.3 * p.position[0] + (p.position[1] - 0.5)) / std::sqrt(1.09);
            CHECK(side >= -1e-4);
        }
        for (const auto& p : run.points("x"))
            for (int c = 0; c < 3; ++c) {
                float lo = c == 1 ? 0 : -1, hi = c == 1 ? 2 : 1;
                CHECK(p.position[static_cast<size_t>(c)] >= lo);
                CHECK(p.position[static_cast<size_t>(c)] <= hi);
            }
        for (const auto& p : run.points("s")) {
            double r = std::hypot(p.position[0], p.position[1] - 1.0, p.position[2]);
            CHECK(r >= 2 - 1e-4);
        }
    }
}

namespace {

// Per object at a random point q in [-20, 20]³: its position and colour as `draw` says.
std::vector<rt::RenderPoint> noiseAt(const std::string& equations, const std::string& draw, int n = 4000) {
    Run run(fmt::format(R"(
        import "std/noise.psys";
        object p(q: vec3) {{ {} point({}, 1); }}
        object e {{ emit p(nrand3() * 20) count {}; kill; }}
        spawn e;)", equations, draw, n));
    run.steps(1, 1.0 / 60);
    auto points = run.points("p");
    REQUIRE(points.size() == static_cast<size_t>(n));
    return points;
}

}  // namespace

TEST_CASE("std/noise: 0 at the lattice, within ±1.5, centred, and not flat") {
    for (const auto& p : noiseAt("", "vec3(noise3(floor(q)), noise2(floor(q.xy)), 0), white")) {
        CHECK(p.position[0] == 0.0f);
    }
    double sum = 0, squares = 0, largest = 0;
    auto points = noiseAt("", "vec3(noise3(q), noise2(q.xz), noise4(vec4(q, q.x * 0.7))), white");
    for (const auto& p : points)
        for (float v : p.position) {
            sum += v;
            squares += double(v) * v;
            largest = std::max(largest, std::abs(double(v)));
        }
    double n = 3.0 * points.size(), mean = sum / n, spread = std::sqrt(squares / n - mean * mean);
    MESSAGE("noise: mean " << mean << ", standard deviation " << spread << ", largest " << largest);
    CHECK(std::abs(mean) < 0.03);
    CHECK(spread > 0.1);
    CHECK(largest < 1.5);
}

TEST_CASE("std/noise: noise3_grad's gradient is the noise's (against central differences)") {
    auto points = noiseAt(R"(
        h = 0.001;
        fd = vec3(noise3(q + vec3(h, 0, 0)) - noise3(q - vec3(h, 0, 0)),
                  noise3(q + vec3(0, h, 0)) - noise3(q - vec3(0, h, 0)),
                  noise3(q + vec3(0, 0, h)) - noise3(q - vec3(0, 0, h))) / (2 * h);)",
                          "fd, noise3_grad(q)");
    double worst = 0;
    for (const auto& p : points)
        for (size_t c = 0; c < 3; ++c) worst = std::max(worst, std::abs(double(p.position[c]) - p.color[c + 1]));
    MESSAGE("the gradient's largest difference from central differences: " << worst);
    CHECK(worst < 0.01);  // (float differences at h = 0.001: about 1e-4 / 0.002)
}

TEST_CASE("std/noise: curl noise has no divergence") {
    auto points = noiseAt(R"(
        h = 0.001;
        c = curl_noise(q);
        div = (curl_noise(q + vec3(h, 0, 0)).x - curl_noise(q - vec3(h, 0, 0)).x
             + curl_noise(q + vec3(0, h, 0)).y - curl_noise(q - vec3(0, h, 0)).y
             + curl_noise(q + vec3(0, 0, h)).z - curl_noise(q - vec3(0, 0, h)).z) / (2 * h);
        ddx = (curl_noise(q + vec3(h, 0, 0)).y - curl_noise(q - vec3(h, 0, 0)).y) / (2 * h);)",
                          "c, vec4(div, ddx, 0, 0)", 2000);
    double worstDiv = 0, typical = 0, size = 0;
    for (const auto& p : points) {
        worstDiv = std::max(worstDiv, std::abs(double(p.color[0])));
        typical += std::abs(double(p.color[1]));  // a derivative that is not 0: the scale
        size += std::hypot(p.position[0], p.position[1], p.position[2]);
    }
    typical /= points.size();
    size /= points.size();
    MESSAGE("curl noise: mean size " << size << ", mean |∂c_y/∂x| " << typical << ", largest |divergence| " << worstDiv);
    CHECK(size > 0.3);
    CHECK(worstDiv < 0.02 * typical * 50);  // (central differences of floats: 1e-3 at worst where derivatives are ~1)
}
