// The chooser under @tolerance (tune/tolerance.h), on the interpreter: every reference
// problem of bench/accuracy at three tolerances is run with what it chose and compared
// with the problem's exact solution — within the tolerance, every frame; what it cannot
// meet it says, with the best it found; a stiff decay gets a stable method; an
// @integrator the author wrote is kept and only the step chosen.
#include <doctest/doctest.h>

#include <atomic>
#include <cmath>
#include <functional>
#include <numbers>
#include <sstream>

#include "driver/compile.h"
#include "interp/interpreter.h"
#include "ir/parser.h"
#include "ir/printer.h"
#include "rt/system.h"
#include "test_support.h"
#include "tests/run_length.h"
#include "tune/tolerance.h"

using namespace psys;
using core::Integrator;

namespace {

constexpr double kFrame = 1.0 / 60;

struct Chosen {
    std::optional<ir::Module> module;
    std::vector<tune::Choice> choices;
    std::string diagnostics;
};

Chosen compileUnderTolerance(const std::string& text, double tolerance = 0,
                             std::function<void(tune::TuneOptions&)> adjust = {}) {
    Chosen c;
    SourceManager sources;
    DiagnosticEngine diags(sources);
    CompileOptions options;
    tune::TuneOptions tune;
    tune.tolerance = tolerance;
    if (adjust) adjust(tune);
    interp::Interpreter trials;
    options.beforePasses = [&](ir::Module& module, opt::PassErrors& messages) {
        c.choices = tune::chooseMethods(module, trials, tune, messages);
    };
    c.module = compileText("tolerance.psys", text, sources, diags, options);
    c.diagnostics = diags.render(false);
    return c;
}

struct Problem {
    const char* file;
    const char* type;
    double seconds;
    std::function<std::array<double, 3>(double)> exact;  // the position at time t
};

std::vector<Problem> problems() {
    const double g = -9.8, pi = std::numbers::pi;
    return {
        {"projectile", "ball", 2, [=](double t) { return std::array<double, 3>{2 * t, 10 * t + g * t * t / 2, 0}; }},
        {"drag", "ball", 4,
         [=](double t) {
             const double k = 0.5, decay = (1 - std::exp(-k * t)) / k;
             return std::array<double, 3>{2 * decay, (g / k) * t + (10 - g / k) * decay, 0};
         }},
        {"spring", "mass", 10, [=](double t) { return std::array<double, 3>{std::cos(2 * pi * t), -2 * pi * std::sin(2 * pi * t), 0}; }},
        {"damped_spring", "mass", 10,
         [=](double t) {
             const double w = 2 * pi, zeta = 0.1, wd = w * std::sqrt(1 - zeta * zeta), a = zeta * w;
             double x = std::exp(-a * t) * (std::cos(wd * t) + a / wd * std::sin(wd * t));
             double v = -std::exp(-a * t) * (a * a / wd + wd) * std::sin(wd * t);
             return std::array<double, 3>{x, v, 0};
         }},
        // Three periods: over a hundred float's rounding of the phase alone is 4e-3 m (below).
        {"orbit", "planet", 20, [](double t) { return std::array<double, 3>{std::cos(t), std::sin(t), 0}; }},
    };
}

// The largest distance of the one object's drawn point from `exact`, frame by frame.
double worstError(ir::Module module, const Problem& p) {
    interp::Interpreter backend;
    rt::System system(std::move(module), backend);
    double worst = 0;
    size_t type = static_cast<size_t>(system.typeIndex(p.type));
    for (long f = 1; f <= std::lround(p.seconds / kFrame); ++f) {
        REQUIRE_FALSE(system.step(kFrame).has_value());
        auto points = system.points(type);
        REQUIRE(points.size() == 1);
        auto e = p.exact(static_cast<double>(f) * kFrame);
        double dx = points[0].position[0] - e[0], dy = points[0].position[1] - e[1], dz = points[0].position[2] - e[2];
        worst = std::max(worst, std::sqrt(dx * dx + dy * dy + dz * dz));
    }
    return worst;
}

}  // namespace

TEST_CASE("every reference problem at 1e-2, 1e-3 and 1e-4 m meets its tolerance with the method chosen") {
    for (const Problem& p : problems()) {
        std::string text = test::readFile(std::string(PSYS_ACCURACY_DIR) + "/" + p.file + ".psys");
        for (double tolerance : {1e-2, 1e-3, 1e-4}) {
            CAPTURE(p.file);
            CAPTURE(tolerance);
            std::ostringstream attribute;
            attribute << "@tolerance(" << tolerance << ", " << p.seconds << ");\n";
            Chosen c = compileUnderTolerance(attribute.str() + text);
            REQUIRE(c.module);
            REQUIRE(c.choices.size() == 1);
            const tune::Choice& choice = c.choices[0];
            CAPTURE(tune::describe(choice.method, choice.subSteps, kFrame));
            CHECK(choice.met);
            CHECK(c.diagnostics.empty());
            CHECK(choice.error <= tolerance);
            double error = worstError(std::move(*c.module), p);
            CHECK(error <= tolerance);
            CHECK(error <= choice.error * 1.5 + 1e-5);  // the prediction is the error, not a bound far above it
            // The cheapest first: nothing cheaper than the choice met the tolerance.
            for (const tune::Trial& t : choice.trials) {
                if (t.cost >= choice.cost) break;
                REQUIRE(t.error);
                CHECK(*t.error > tolerance);
            }
        }
    }
}

TEST_CASE("a tolerance float state cannot reach is met in double: the orbit to 1e-4 m over 100 periods" *
          doctest::skip(test::kSanitized) * doctest::test_suite("long")) {
    std::string text = test::readFile(std::string(PSYS_ACCURACY_DIR) + "/orbit.psys");
    Chosen c = compileUnderTolerance("@tolerance(1e-4, 628.3);\n" + text);
    REQUIRE(c.module);
    REQUIRE(c.choices.size() == 1);
    const tune::Choice& choice = c.choices[0];
    CAPTURE(tune::explain(c.choices));
    CHECK(choice.met);
    CHECK(c.diagnostics.empty());
    CHECK(choice.precision == core::Precision::Double);
    CHECK(c.module->objects[0].attributes.precision == core::Precision::Double);
    CHECK(choice.floor < 1e-5);  // the reference, rk4 in double, is good to far better than the tolerance
    // Every candidate in float was tried first and missed: their rounding alone is past it.
    for (const tune::Trial& t : choice.trials) {
        if (t.precision != core::Precision::Float || !t.error) continue;
        CHECK(*t.error > 1e-4);
    }
    Problem orbit{"orbit", "planet", 628.3, [](double t) { return std::array<double, 3>{std::cos(t), std::sin(t), 0}; }};
    CHECK(worstError(std::move(*c.module), orbit) <= 1e-4);
}

TEST_CASE("a tolerance no candidate can reach is a located warning with the best found, never a silent miss") {
    std::string text = test::readFile(std::string(PSYS_ACCURACY_DIR) + "/orbit.psys");
    Chosen c = compileUnderTolerance("@tolerance(1e-9, 20);\n" + text);  // below the drawn point's own rounding
    REQUIRE(c.module);
    REQUIRE(c.choices.size() == 1);
    CHECK_FALSE(c.choices[0].met);
    CHECK(c.diagnostics.find("tolerance.psys:4:8: warning: no integrator and sub-step keeps `planet` within 1e-09 m "
                             "over 20 s") != std::string::npos);
    CHECK(c.diagnostics.find("the closest, ") != std::string::npos);
}

TEST_CASE("a stiff decay under a tolerance gets a method that keeps it stable, and no stability warning") {
    std::string text = test::readFile(std::string(PSYS_ACCURACY_DIR) + "/stiff_fountain.psys");
    Chosen c = compileUnderTolerance(text, 1e-3);  // the default tolerance (psysc --tolerance)
    REQUIRE(c.module);
    REQUIRE(c.choices.size() == 1);  // the drops: the source integrates nothing
    CHECK(c.choices[0].object == "drop");
    CHECK_FALSE(c.choices[0].own);
    CHECK(c.choices[0].met);
    CHECK(c.diagnostics.empty());
    CHECK(c.choices[0].error <= 1e-3);
    interp::Interpreter backend;
    rt::System system(std::move(*c.module), backend);
    for (int f = 0; f < 120; ++f) REQUIRE_FALSE(system.step(kFrame).has_value());
    CHECK(system.stats().types[static_cast<size_t>(system.typeIndex("drop"))].unstable == 0);
    CHECK(system.stats().types[static_cast<size_t>(system.typeIndex("drop"))].live > 100);
}

TEST_CASE("an @integrator the author wrote is kept under a tolerance: only the sub-step is chosen") {
    std::string text = test::readFile(std::string(PSYS_ACCURACY_DIR) + "/spring.psys");
    text.replace(text.find("object mass"), 11, "@integrator(midpoint) @tolerance(1e-2, 10) object mass");
    Chosen c = compileUnderTolerance(text);
    REQUIRE(c.choices.size() == 1);
    CHECK(c.choices[0].methodFixed);
    CHECK(c.choices[0].method == Integrator::Midpoint);
    CHECK(c.choices[0].subSteps == 16);  // midpoint at 1/60 is 0.7 m off the spring over 10 s, at 1/480 1.1e-2
    CHECK(c.choices[0].met);
    for (const tune::Trial& t : c.choices[0].trials) CHECK(t.method == Integrator::Midpoint);
    REQUIRE(c.module);
    const ir::Object& mass = c.module->objects[0];
    CHECK(mass.attributes.integrator == Integrator::Midpoint);
    CHECK(mass.attributes.step == doctest::Approx(kFrame / c.choices[0].subSteps));
}

TEST_CASE("the choice is deterministic and --explain says what was tried") {
    std::string text = "@tolerance(1e-3, 10);\n" + test::readFile(std::string(PSYS_ACCURACY_DIR) + "/damped_spring.psys");
    Chosen a = compileUnderTolerance(text), b = compileUnderTolerance(text);
    REQUIRE(a.choices.size() == 1);
    CHECK(a.choices[0].method == b.choices[0].method);
    CHECK(a.choices[0].subSteps == b.choices[0].subSteps);
    CHECK(a.choices[0].error == b.choices[0].error);
    std::string said = tune::explain(a.choices);
    CHECK(said.find("mass: @tolerance(0.001 m over 10 s): chose ") != std::string::npos);
    CHECK(said.find("reference: rk4 in double (@precision(double)) with ") != std::string::npos);
    CHECK(said.find("tried euler") != std::string::npos);
}

TEST_CASE("objects that integrate nothing, or state no tolerance, are left as written") {
    Chosen c = compileUnderTolerance(R"(
        @tolerance(1e-3) object still { point(vec3(age, 0, 0), white, 1); }
        object thrown { pos = integrate(vec3(1, 0, 0)); point(pos, white, 1); }
        spawn still; spawn thrown;)");
    REQUIRE(c.module);
    CHECK(c.choices.empty());
    CHECK_FALSE(c.module->objects[1].attributes.integrator.has_value());
}

TEST_CASE("the chooser's trial systems run beside a nested type's late kills") {
    // The trials run the whole file: a step there once settled two late launches of the
    // nested type into one emptied list (tests/programs/step_late_kills_beside_nested.psys).
    Chosen c = compileUnderTolerance(R"(
        @tolerance(1e-2) object thrown { pos = integrate(vec3(1, 2, 0)); point(pos, white, 1); }
        object a { kill when age > 100; }
        object b { emit c at 60 per second; object c { kill when age > 100; } }
        spawn thrown; spawn a; spawn b;)");
    REQUIRE(c.module);
    CHECK(c.choices.size() == 1);
}

TEST_CASE("@tolerance is carried into the IR, printed and parsed back") {
    SourceManager sources;
    DiagnosticEngine diags(sources);
    CompileOptions lowerOnly;
    lowerOnly.pipeline.optimize = false;
    auto module = compileText("t.psys", "@tolerance(1e-3, 30) object a { pos = integrate(vec3(1, 0, 0)); point(pos, white, 1); }\n"
                                        "@tolerance(0.5) object b { pos = integrate(vec3(1, 0, 0)); point(pos, white, 1); }\n"
                                        "spawn a; spawn b;", sources, diags, lowerOnly);
    REQUIRE(module);
    CHECK(module->objects[0].attributes.tolerance == doctest::Approx(1e-3));
    CHECK(module->objects[0].attributes.toleranceOver == 30);
    CHECK(module->objects[1].attributes.toleranceOver == 0);  // the default time
    std::string text = ir::print(*module);
    CHECK(text.find("  attribute tolerance 0.001 30\n") != std::string::npos);
    std::string error;
    auto back = ir::parseModule(text, error);
    INFO(error);
    REQUIRE(back);
    CHECK(back->objects[0].attributes == module->objects[0].attributes);
    CHECK(back->objects[1].attributes == module->objects[1].attributes);
}

TEST_CASE("an object that draws nothing under a tolerance is a warning and keeps what it was written with") {
    Chosen c = compileUnderTolerance(R"(
        @tolerance(1e-3, 2) object hidden { pos = integrate(vec3(1, 0, 0)); kill when pos.x > 5; }
        spawn hidden;)");
    REQUIRE(c.module);
    REQUIRE(c.choices.size() == 1);
    CHECK(c.choices[0].trials.empty());
    CHECK_FALSE(c.module->objects[0].attributes.integrator.has_value());
    CHECK(c.diagnostics.find("warning: `hidden` draws nothing in its first 2 s: its tolerance cannot be measured") !=
          std::string::npos);
    CHECK(tune::explain(c.choices) == "hidden: @tolerance(0.001 m over 2 s): nothing drawn to measure; integrator and "
                                      "step as written\n");
}

TEST_CASE("choices cost at most their budget of steps whatever the horizons, and say when it ran out") {
    // @tolerance(1e-3, 1000) ran 12 million steps (a minute; 1e6 s would have taken hours),
    // and a horizon of 1e20 s overflowed the count of frames.
    const std::string ball = "@tolerance(1e-3, HORIZON) object ball(v0: vec3) {\n"
                             "    vel = v0 + integrate(vec3(0, -9.8, 0) - 0.1 * vel);\n"
                             "    pos = integrate(vel); point(pos, white, 1); }\n"
                             "object thrower { emit ball(vec3(rand(), 10, 0)) count 3; }\nspawn thrower;";
    for (const char* horizon : {"1000", "1e20"}) {
        INFO(horizon);
        std::string text = ball;
        text.replace(text.find("HORIZON"), 7, horizon);
        Chosen c = compileUnderTolerance(text, 0, [](tune::TuneOptions& t) { t.budget = 20000; });
        REQUIRE(c.module);
        REQUIRE(c.choices.size() == 1);
        CHECK(c.choices[0].exhausted);
        CHECK_FALSE(c.choices[0].met);
        CHECK(c.choices[0].steps <= 20000 + 16);
        CHECK(c.diagnostics.find("stopped at their budget of 20000 steps before a choice") != std::string::npos);
        CHECK_FALSE(c.module->objects[0].attributes.integrator.has_value());  // as written
    }
    // The budget is the program's: a second object under a tolerance gets what is left.
    {
        std::string two = ball;
        two.replace(two.find("HORIZON"), 7, "1000");
        two += "\n@tolerance(1e-3, 1000) object ball2 { pos = integrate(vec3(1, 0, 0)); point(pos, white, 1); }\nspawn ball2;";
        Chosen c = compileUnderTolerance(two, 0, [](tune::TuneOptions& t) { t.budget = 20000; });
        REQUIRE(c.choices.size() == 2);
        CHECK(c.choices[0].steps + c.choices[1].steps <= 20000 + 32);
        CHECK(c.choices[1].exhausted);
    }
    // Within the budget the horizon is measured in full.
    std::string text = ball;
    text.replace(text.find("HORIZON"), 7, "2");
    Chosen c = compileUnderTolerance(text, 0, [](tune::TuneOptions& t) { t.budget = 20000; });
    REQUIRE(c.choices.size() == 1);
    CHECK_FALSE(c.choices[0].exhausted);
    CHECK(c.choices[0].met);
}

TEST_CASE("trials stop at once when cancelled (an editor's newer text), and nothing is chosen or said") {
    std::atomic<bool> cancelled{true};
    Chosen c = compileUnderTolerance(
        "@tolerance(1e-4, 600) object ball { pos = integrate(vec3(1, 0, 0) + integrate(vec3(0, -1, 0))); "
        "point(pos, white, 1); }\nspawn ball;",
        0, [&](tune::TuneOptions& t) { t.cancelled = &cancelled; });
    CHECK(c.choices.empty());  // no object is tried once cancelled
    CHECK(c.diagnostics.find("warning") == std::string::npos);
    CHECK_FALSE(c.module->objects[0].attributes.integrator.has_value());
}

TEST_CASE("a reference that does not settle is said to be untrustworthy, and nothing is chosen by it") {
    // A stiff spring: rk4 in double diverges at 4 sub-steps a frame; the chooser once took
    // its distance from 8 as the reference's error and said "within 8.6e+27 m".
    Chosen c = compileUnderTolerance("@tolerance(0.01) object spring(v0: vec3) {\n"
                                     "    vel = v0 + integrate(-pos * 1e6); pos = integrate(vel); point(pos, white, 1); }\n"
                                     "object maker { emit spring(vec3(rand(), 1, 0)) count 2; }\nspawn maker;");
    REQUIRE(c.module);
    REQUIRE(c.choices.size() == 1);
    CHECK_FALSE(c.choices[0].trusted);
    CHECK(c.diagnostics.find("`spring`'s error cannot be measured: the reference, rk4 in double, does not settle") !=
          std::string::npos);
    CHECK(c.diagnostics.find("within") == std::string::npos);
    CHECK_FALSE(c.module->objects[0].attributes.integrator.has_value());
}
