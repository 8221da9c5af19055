// The run-time and the interpreter, checked against exact answers: the Euler recurrence,
// emission counts and times, kill frames, live parent reads, determinism, and the
// extremes (docs/runtime.md, "The extremes, and what happens").
#include <doctest/doctest.h>
#include <fmt/format.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>

#include "driver/compile.h"
#include "interp/interpreter.h"
#include "rt/memory.h"
#include "rt/system.h"
#include "tests/run_length.h"
#include "tests/unexpected_op.h"
#include "run.h"
#include "test_support.h"

using namespace psys;
using test::bitwise;
using test::compareRuns;
using test::Run;

TEST_CASE("a projectile under the default method (semi-implicit Euler) is its recurrence, bit for bit") {
    Run run(test::kProjectile);
    const float dt = 1.0f / 60.0f;
    float av = 0, apx = 0, apy = 0;  // the integrals of gravity (y) and of velocity
    for (int frame = 1; frame <= 300; ++frame) {
        run.steps(1, 1.0 / 60.0);
        av = av + (-9.8f) * dt;        // vel = v0 + ∫g: this update's value
        float vy = 10.0f + av, vx = 1.0f + 0.0f;
        apx = apx + vx * dt;           // pos = ∫vel, with this update's velocity
        apy = apy + vy * dt;
        const auto& p = run.points("p");
        REQUIRE(p.size() == 1);
        CHECK(p[0].position[0] == apx);
        CHECK(p[0].position[1] == apy);
    }
    // and close to the closed form p0 + v0·t + ½·g·t² (Euler's error is O(dt))
    float t = 5.0f;
    CHECK(run.points("p")[0].position[1] == doctest::Approx(10 * t - 4.9f * t * t).epsilon(0.01));
}

TEST_CASE("a rate-R emitter over T seconds creates R·T ± 1 objects") {
    for (double rate : {1.0, 7.5, 50.0, 600.0}) {
        Run run("object s { point(origin, white, 1); }\nobject e { emit s at " + std::to_string(rate) +
                " per second; }\nspawn e;");
        run.steps(600, 1.0 / 60);  // 10 s
        double created = static_cast<double>(run.stats("s").created);
        CHECK(std::abs(created - rate * 10) <= 1);
    }
}

TEST_CASE("objects spawned within one frame have evenly spaced ages") {
    Run run("object s { point(origin, white, age); }\nobject e { emit s at 600 per second; }\nspawn e;");
    run.steps(1, 1.0 / 60);
    std::vector<float> ages;
    for (auto& p : run.points("s")) ages.push_back(p.size);
    REQUIRE(ages.size() == 10);
    std::sort(ages.begin(), ages.end());
    for (size_t i = 0; i < ages.size(); ++i) CHECK(ages[i] == doctest::Approx(i / 600.0).epsilon(1e-4));
}

TEST_CASE("a rate of 0.25 per second emits at 4 s, 8 s, 12 s") {
    Run run("object s { point(origin, white, age); }\nobject e { emit s at 0.25 per second; }\nspawn e;");
    for (int frame = 1; frame <= 60 * 12; ++frame) {
        run.steps(1, 1.0 / 60);
        uint64_t expected = static_cast<uint64_t>(frame / 240);
        REQUIRE_MESSAGE(run.stats("s").created == expected, "frame " << frame);
    }
}

TEST_CASE("kill happens at the first update where the condition holds") {
    Run run("object a { point(origin, white, age); kill when age > 1; }\nspawn a;");
    for (int frame = 1; frame <= 4; ++frame) {
        run.steps(1, 0.25);
        CHECK(run.stats("a").live == 1);  // ages 0.25 … 1.0
    }
    run.steps(1, 0.25);  // age 1.25
    CHECK(run.stats("a").live == 0);
    CHECK(run.stats("a").killed == 1);
}

TEST_CASE("a burst happens at creation, before a bare kill removes the emitter") {
    Run run("object s { point(origin, white, 1); }\nobject b { emit s count 3; kill; }\nspawn b;");
    run.steps(1, 1.0 / 60);
    CHECK(run.stats("s").created == 3);
    CHECK(run.stats("b").live == 0);
}

TEST_CASE("a child reads its parent live, then the frozen value with alive false") {
    Run run(R"(
        object parent {
            x = age;
            emit child count 1;
            kill when age > 1;
            object child {
                point(vec3(parent.x, parent.alive ? 1 : 0, 0), white, 1);
            }
        }
        spawn parent;)");
    for (int frame = 1; frame <= 4; ++frame) {
        run.steps(1, 0.25);
        const auto& c = run.points("parent.child");
        REQUIRE(c.size() == 1);
        CHECK(c[0].position[0] == doctest::Approx(0.25 * frame));  // the parent's age this frame
        CHECK(c[0].position[1] == 1);
    }
    run.steps(3, 0.25);  // the parent dies at age 1.25
    const auto& c = run.points("parent.child");
    REQUIRE(c.size() == 1);
    CHECK(c[0].position[0] == doctest::Approx(1.0));  // its last exported value, frozen
    CHECK(c[0].position[1] == 0);
    CHECK(run.stats("parent").frozen == 1);
}

TEST_CASE("a frozen parent is freed after its last reader dies") {
    Run run(R"(
        object parent {
            emit child count 2;
            kill when age > 0.5;
            object child { point(vec3(parent.age), white, 1); kill when age > 1; }
        }
        spawn parent;)");
    run.steps(3, 0.25);
    CHECK(run.stats("parent").frozen == 1);
    run.steps(2, 0.25);
    CHECK(run.stats("parent.child").live == 0);
    CHECK(run.stats("parent").frozen == 0);
}

// The rule of the step's end (rt/ledger.h): a type's deaths freed in the order they came,
// the children's before their parents' — whatever the order of their kills in the step.
// Parents of given lives, each with one child of a given life that reads it, and a
// trigger that makes more: which rows the trigger's take tells the free stack's order.
constexpr const char* kParentsAndReaders = R"(
        object p(life: float, childLife: float) {
            emit c(childLife) count 1;
            kill when age > life;
            point(vec3(life, childLife, 0), white, 1);
            object c(l: float) {
                point(vec3(p.age, 0, 1), white, 1);
                kill when age > l;
            }
        }
        trigger again(life: float) { emit p(life, 0.1) count 1; })";

TEST_CASE("a parent dying beside its last reader is freed in its own place among its type's deaths") {
    Run run(std::string(kParentsAndReaders) + R"(
        spawn p(1.1, 1.1);  // row 0: dies at 1.25 s, its child in the same step (after it)
        spawn p(1.1, 0.1);  // row 1: its child gone at 0.25 s; dies at 1.25 s, read by nobody)");
    run.steps(5, 0.25);
    CHECK(run.stats("p").live == 0);
    CHECK(run.stats("p").frozen == 0);
    // Freed in the order they died (row 0, then row 1): the first object the trigger
    // creates takes the row freed last. (Had row 0 waited for its child's kill, after row
    // 1's own, the order would be the other.)
    REQUIRE_FALSE(run.system->fire("again", std::vector<float>{9}).has_value());
    REQUIRE_FALSE(run.system->fire("again", std::vector<float>{8}).has_value());
    run.steps(1, 0.25);
    const auto& p = run.points("p");
    REQUIRE(p.size() == 2);
    CHECK(p[0].position[0] == 8);
    CHECK(p[1].position[0] == 9);
}

// …and a parent that died before, whose last reader goes now: after its type's deaths of
// the step, in row order.
TEST_CASE("parents whose last readers go in one step are freed after that step's deaths of their type, in row order") {
    Run run(std::string(kParentsAndReaders) + R"(
        spawn p(0.1, 1.1);  // row 0: frozen at 0.25 s, its child dies at 1.25 s
        spawn p(0.1, 1.1);  // row 1: the same
        spawn p(1.1, 0.1);  // row 2: dies at 1.25 s, its child long gone)");
    run.steps(5, 0.25);
    CHECK(run.stats("p").frozen == 0);
    // The stack: row 2 (its own death), then rows 0 and 1 (their readers gone): a trigger's
    // objects take rows 1, 0, 2.
    for (float life : {7.0f, 8.0f, 9.0f}) REQUIRE_FALSE(run.system->fire("again", std::vector<float>{life}).has_value());
    run.steps(1, 0.25);
    const auto& p = run.points("p");
    REQUIRE(p.size() == 3);
    CHECK(p[0].position[0] == 8);
    CHECK(p[1].position[0] == 7);
    CHECK(p[2].position[0] == 9);
}

TEST_CASE("the same seed gives the same run — another seed another") {
    std::string fireworks = test::readFile((std::filesystem::path(PSYS_SAMPLES_DIR) / "fireworks.psys").string());
    auto positions = [&](uint32_t seed) {
        rt::SystemOptions options;
        options.seed = seed;
        Run run(fireworks, options);
        run.steps(120, 1.0 / 60);
        std::vector<float> all;
        for (auto& p : run.points("spark")) all.insert(all.end(), p.position.begin(), p.position.end());
        return all;
    };
    auto a = positions(7), b = positions(7), c = positions(8);
    CHECK(!a.empty());
    CHECK(a == b);
    CHECK(a != c);
}

TEST_CASE("every sample compiles, verifies and runs 600 frames at dt = 1/60 (200 sanitized)" * doctest::test_suite("long")) {
    int count = 0;
    for (auto& entry : std::filesystem::directory_iterator(PSYS_SAMPLES_DIR)) {
        if (entry.path().extension() != ".psys") continue;
        ++count;
        INFO(entry.path().filename().string());
        std::string text = test::readFile(entry.path().string());
        Run run(text);
        run.steps(test::sweepFrames(text), 1.0 / 60);
        for (size_t t = 0; t < run.system->typeCount(); ++t) run.system->points(t);
        CHECK(run.system->stats().nonFiniteRender == 0);
    }
    CHECK(count >= 12);
}

// ---------------------------------------------------------------- extremes

TEST_CASE("dt = 0 changes nothing — negative, NaN and infinite dt are refused and counted") {
    Run run("object a { pos = integrate(vec3(1)); point(pos, white, age); }\nspawn a;");
    run.steps(1, 0.5);
    auto before = run.points("a");
    run.steps(10, 0.0);
    CHECK(run.points("a")[0].position == before[0].position);
    CHECK(run.points("a")[0].size == before[0].size);
    for (double bad : {-1.0, std::nan(""), static_cast<double>(INFINITY)}) {
        auto error = run.system->step(bad);
        REQUIRE(error.has_value());
        CHECK(error->find("finite, non-negative") != std::string::npos);
    }
    CHECK(run.system->stats().rejectedSteps == 3);
    CHECK(run.system->time() == 0.5);

    // Not even a count of updates: `prev` and `->` do not advance.
    Run counter("object a { n = 0 -> prev(n) + 1; point(origin, white, n); }\nspawn a;");
    counter.steps(1, 1.0 / 60);
    float n = counter.points("a")[0].size;
    counter.steps(100, 0.0);
    CHECK(counter.points("a")[0].size == n);
}

TEST_CASE("tiny steps and a 10 s hitch") {
    Run run("object s { point(origin, white, age); kill when age > 3; }\n"
            "object e { emit s at 100 per second; }\nspawn e;");
    run.steps(1000, 1e-7);
    CHECK(run.system->time() == doctest::Approx(1e-4));
    run.steps(1, 10.0);  // a hitch: every object of it gets its exact creation time
    CHECK(run.stats("s").created == 1000);
    CHECK(run.stats("s").live == doctest::Approx(300).epsilon(0.01));
    for (auto& p : run.points("s")) CHECK(p.size <= 3.0f);
}

TEST_CASE("emission rates at the extremes") {
    SUBCASE("rate 0 never emits") {
        Run run("object s { point(origin, white, 1); }\nobject e { emit s at 0 per second; }\nspawn e;");
        run.steps(600, 1.0 / 60);
        CHECK(run.stats("s").created == 0);
    }
    SUBCASE("rate 1e-3 emits once, at 1000 s") {
        Run run("object s { point(origin, white, 1); }\nobject e { emit s at 1e-3 per second; }\nspawn e;");
        run.steps(999, 1.0);
        CHECK(run.stats("s").created == 0);
        run.steps(1, 1.0);
        CHECK(run.stats("s").created == 1);
    }
    SUBCASE("rate 1e9 fills the capacity and counts what it drops") {
        Run run("@capacity(1000) object s { point(origin, white, 1); }\nobject e { emit s at 1e9 per second; }\nspawn e;");
        run.steps(3, 1.0 / 60);
        CHECK(run.stats("s").live == 1000);
        CHECK(run.stats("s").dropped > 40'000'000);
        CHECK(run.system->pool(run.type("s")).rows() == 1000);  // memory bounded
    }
    SUBCASE("negative and NaN rates emit nothing and are counted") {
        Run run("extern r: float = 0;\nobject s { point(origin, white, 1); }\n"
                "object e { emit s at r per second; emit s at sqrt(r) per second; }\nspawn e;");
        float negative = -5;  // the first rate is -5, the second sqrt(-5): NaN
        REQUIRE_FALSE(run.system->setExtern("r", {&negative, 1}));
        run.steps(10, 1.0 / 60);
        CHECK(run.stats("s").created == 0);
        CHECK(run.system->stats().invalidEmissions == 22);  // two sites: 10 steps and the emitter's update at creation
    }
}

TEST_CASE("after 10^7 s ages are still exact to a millisecond") {
    Run run("object a { point(origin, white, age); }\ntrigger go { emit a count 1; }");
    run.steps(1, 1e7);
    REQUIRE_FALSE(run.system->fire("go", {}));
    run.steps(1, 0.001);
    REQUIRE(run.points("a").size() == 1);
    CHECK(run.points("a")[0].size == doctest::Approx(0.001).epsilon(1e-3));
}

TEST_CASE("NaN and infinity set on an extern are refused and counted — it keeps its last good value") {
    Run run("extern w: vec3 = 0;\nobject a(k: float) { point(vec3(k) + w * k, white, 1); }\n"
            "spawn a(0); spawn a(1);");
    float good[3] = {1, 2, 3};
    REQUIRE_FALSE(run.system->setExtern("w", good));
    float bad[3] = {std::nanf(""), 0, INFINITY};
    auto error = run.system->setExtern("w", bad);
    REQUIRE(error.has_value());
    CHECK(*error == "extern `w` takes finite values only; it keeps its value");
    CHECK(run.system->externValue("w")->f[0] == 1);
    run.steps(1, 1.0 / 60);
    CHECK(run.points("a").size() == 2);
    CHECK(run.system->stats().nonFiniteExterns == 1);
    CHECK(run.system->stats().nonFiniteRender == 0);
}

TEST_CASE("a value outside an extern's range is refused and counted — it keeps its value") {
    Run run("extern k: float = 1 range(0, 2);\nextern v: vec3 = 0 range(-1, 1);\n"
            "object a { point(v, white, k); }\nspawn a;");
    float five = 5, two = 2;
    auto error = run.system->setExtern("k", {&five, 1});
    REQUIRE(error.has_value());
    CHECK(*error == "extern `k`: 5 is outside its range [0, 2]; it keeps its value");
    CHECK(run.system->externValue("k")->f[0] == 1);
    CHECK_FALSE(run.system->setExtern("k", {&two, 1}));  // the bounds are inside
    float v[3] = {0, -1.5f, 0};
    CHECK(run.system->setExtern("v", v).has_value());
    CHECK(run.system->stats().outOfRangeExterns == 2);
    run.steps(1, 1.0 / 60);
    CHECK(run.points("a")[0].size == 2);
}

TEST_CASE("a point that is not finite is not drawn, and is counted") {
    Run run("object a(k: float) { point(vec3(k) / k, white, 1); }\nspawn a(0); spawn a(1);");
    run.steps(1, 1.0 / 60);
    CHECK(run.points("a").size() == 1);
    CHECK(run.system->stats().nonFiniteRender == 1);
}

TEST_CASE("a step that would take the time past 2^32 s is refused and counted, and up to it steps run") {
    Run run("object a { point(vec3(age), white, 1); kill when age > 1e12; }\nspawn a;");
    auto error = run.system->step(1e308);  // (the time was +inf from the second step)
    REQUIRE(error);
    CHECK(error->find("would take the time past 4294967296 s") != std::string::npos);
    CHECK(run.system->stats().rejectedSteps == 1);
    CHECK(run.system->time() == 0);
    CHECK_FALSE(run.system->step(rt::System::kLatestTime - 1));
    CHECK_FALSE(run.system->step(1));  // exactly the latest time
    CHECK(run.system->time() == rt::System::kLatestTime);
    CHECK(run.system->step(1.0 / 60).has_value());
    CHECK(run.system->stats().rejectedSteps == 2);
    CHECK(run.system->time() == rt::System::kLatestTime);
    CHECK(run.points("a").size() == 1);
}

TEST_CASE("a bool extern takes 0 or 1 (true or false) only, and keeps its value otherwise") {
    Run run("extern lit: bool = false;\nobject a { point(vec3(0), if lit then white else red, 1); }\nspawn a;");
    for (float v : {2.0f, 0.5f, -1.0f})
        CHECK(run.system->setExtern("lit", {&v, 1}).value() ==
              fmt::format("extern `lit` is a bool: it takes true or false (or 1 or 0), not {}; it keeps its value", v));
    float on = 1;
    CHECK_FALSE(run.system->setExtern("lit", {&on, 1}).has_value());
    CHECK(run.system->externValue("lit")->f[0] == 1);
}

TEST_CASE("host API misuse is an error value") {
    Run run("extern w: vec3 = 0;\nobject a(p: vec3) { point(p, white, 1); }\ntrigger go(at_pos: vec3) { emit a(at_pos) count 2; }");
    float one = 1;
    CHECK(run.system->setExtern("nope", {&one, 1}).value() == "there is no extern `nope`");
    CHECK(run.system->setExtern("w", {&one, 1}).value() == "extern `w` is a vec3: it takes 3 values, not 1");
    CHECK(run.system->setExtern(7, {&one, 1}).value() == "there is no extern with handle 7");
    CHECK(run.system->externHandle("nope") == -1);
    float wind[3] = {4, 5, 6};
    CHECK_FALSE(run.system->setExtern(run.system->externHandle("w"), wind).has_value());
    CHECK(run.system->fire("boom", {}).value() == "there is no trigger `boom` (the triggers are `go`)");
    CHECK(run.system->fire("go", {&one, 1}).value() == "trigger `go` takes 3 numbers, not 1");
    // A trigger's values are finite numbers, as an extern's: a NaN would reach every object it makes.
    float bad[3] = {0, NAN, 0}, huge[3] = {0, INFINITY, 0};
    CHECK(run.system->fire("go", bad).value() == "trigger `go` takes finite numbers, not nan");
    CHECK(run.system->fire("go", huge).value() == "trigger `go` takes finite numbers, not inf");
    CHECK(run.system->stats().types[0].created == 0);
    float at[3] = {1, 2, 3};
    REQUIRE_FALSE(run.system->fire("go", at));
    const auto& p = run.points("a");
    REQUIRE(p.size() == 2);
    CHECK(p[0].position == std::array<float, 3>{1, 2, 3});
}

TEST_CASE("@step(h) advances an object in sub-steps no longer than h") {
    // x' = -x: one Euler step of 1 s gives 0; four sub-steps of 0.25 s give 0.75^4.
    auto after = [](const std::string& attribute) {
        Run run(attribute + " object a { x = 1 -> prev(x) - prev(x) * dt; point(vec3(x), white, 1); }\nspawn a;");
        run.steps(1, 1.0);
        return run.points("a").at(0).position[0];
    };
    CHECK(after("") == 0.0f);
    CHECK(after("@step(0.25)") == doctest::Approx(std::pow(0.75, 4)));
    CHECK(after("@step(0.3)") == doctest::Approx(std::pow(0.75, 4)));  // 4 equal sub-steps of 0.25
}

TEST_CASE("the optimizer leaves every sample's output unchanged, bit for bit, over 600 frames (200 sanitized)" * doctest::test_suite("long")) {
    size_t points = test::compareWithUnoptimized(false, {}, test::kLongRun, bitwise, test::kSanitized);
    CHECK(points > 100000);
}

TEST_CASE("with relaxed maths every sample's output stays within 1e-4 of max(1, |value|) over 600 frames (200 sanitized)" * doctest::test_suite("long")) {
    // What differs: the last bits of reassociated sums and of x/c as x·(1/c), integrals of
    // constants taken as c·age instead of a float sum over 600 steps (the closed form is the
    // more accurate of the two), c + integrate(e) accumulated as one integral starting
    // at c, and a slot computed again from the stored slots at age − dt (recompute-state)
    // instead of stored. The fold rounds relative to the summands, not to their sum: where a
    // position crosses zero its error is a few ulps of the start position, so the
    // difference is measured against max(1, |value|), as the backends' are. Measured worst:
    // 5.4e-6 (for values above 0.01, 1.9e-4 of the value itself: the fire's positions).
    float worst = 0;
    size_t points = test::compareWithUnoptimized(true, {}, test::kLongRun, [&](float a, float b) {
        float d = std::fabs(a - b) / std::max(std::fabs(a), 1.0f);
        if (std::isfinite(d)) worst = std::max(worst, d);
        return d <= 1e-4f;
    }, test::kSanitized);
    MESSAGE("relaxed vs unoptimized: " << points << " points, worst " << worst << " of max(1, |value|)");
    CHECK(points > (test::kSanitized ? 20000u : 100000u));
}

TEST_CASE("recompute-state runs only with relaxed maths") {
    auto slots = [](bool relaxed) {
        std::string fire = test::readFile(std::string(PSYS_SAMPLES_DIR) + "/fire.psys");
        ir::Module m = test::compileModule(fire, true, std::nullopt, relaxed);
        return m.object("part")->state.size();
    };
    CHECK(slots(false) == 3);  // prev(acc), vel, pos
    CHECK(slots(true) == 2);
}

namespace {

// The interpreter, counting the render launches it runs.
struct CountingBackend : rt::Backend {
    interp::Interpreter inner;
    size_t renders = 0;
    std::string name() const override { return "counting"; }
    rt::Memory& memory() override { return inner.memory(); }
    rt::RowsResult run(const rt::RowsLaunch& l) override {
        renders += l.kernel->kind == ir::KernelKind::Render;
        return inner.run(l);
    }
    void run(const rt::ChildrenLaunch& l) override { inner.run(l); }
};

}  // namespace

TEST_CASE("drawing as the step goes draws what drawing after it draws, bit for bit, whenever the host draws" * doctest::test_suite("long")) {
    std::vector<std::function<bool(int)>> patterns = {
        [](int) { return true; }, [](int f) { return f % 3 == 2; }, [](int f) { return f % 7 < 4; }};
    size_t bytes = 0;
    for (const std::string& text : test::samplesAndPrograms())
        for (const auto& drawOn : patterns) {
            interp::Interpreter a, b;
            std::string inStep = test::hostSees(text, a, true, test::bookkeepingFrames(90), drawOn);
            std::string after = test::hostSees(text, b, false, test::bookkeepingFrames(90), drawOn);
            CHECK(inStep == after);
            bytes += inStep.size();
        }
    CHECK(bytes > (test::kSanitized ? 500000u : 1000000u));
}

TEST_CASE("a step after a drawn one draws as it goes: draw() then runs no render launch") {
    for (bool inStep : {true, false}) {
        CountingBackend backend;
        rt::SystemOptions options;
        options.drawInStep = inStep;
        rt::System system(test::compileModule(test::readFile(PSYS_SAMPLES_DIR "/fountain.psys")), backend, options);
        auto drop = static_cast<size_t>(system.typeIndex("drop"));
        system.step(1.0 / 60);
        system.step(1.0 / 60);
        size_t before = backend.renders;
        CHECK(system.draw(drop).drawn > 0);
        CHECK(backend.renders > before);  // the first draw: no step drew before it
        system.step(1.0 / 60);
        size_t during = backend.renders;
        CHECK((during > before + 1) == inStep);  // the step rendered the drops as it went
        size_t drawn = system.draw(drop).drawn;
        CHECK(drawn > 0);
        CHECK((backend.renders == during) == inStep);
        // A new extern value: the render kernel may read it, so draw() renders again.
        system.step(1.0 / 60);
        REQUIRE_FALSE(system.setExtern("population", std::vector<float>{4000}));
        during = backend.renders;
        CHECK(system.draw(drop).drawn > 0);
        CHECK(backend.renders > during);
    }
}

namespace {

// The interpreter, listing the rows each update killed (RowsResult::killedRows) and
// leaving no kill flag behind: what the run-time kills must come from the list.
struct ListingBackend : rt::Backend {
    interp::Interpreter inner;
    std::vector<uint32_t> rows;
    std::string name() const override { return "listing"; }
    rt::Memory& memory() override { return inner.memory(); }
    rt::RowsResult run(const rt::RowsLaunch& l) override {
        rt::RowsResult r = inner.run(l);
        bool kills = l.kernel->findOne(ir::YieldKind::Kill) != nullptr;
        if (!kills || !l.columns[rt::ColumnLayout::kKill].valid()) return r;
        auto* flags = rt::hostData<uint8_t>(memory(), l.columns[rt::ColumnLayout::kKill]);
        rows.clear();
        for (size_t i = l.begin; i < l.end; ++i)
            if (flags[i]) {
                rows.push_back(static_cast<uint32_t>(i));
                flags[i] = 0;
            }
        r.killedRows = rows;
        return r;
    }
    void run(const rt::ChildrenLaunch& l) override { inner.run(l); }
};

}  // namespace

TEST_CASE("a backend that lists the rows an update killed is taken at its word, without the flags") {
    // The fountain's drops only die (no emissions): the run-time takes the list the
    // backend gives (the GLSL backend's, compacted on the GPU) instead of scanning flags.
    std::string text = test::readFile(PSYS_SAMPLES_DIR "/fountain.psys");
    ListingBackend listing;
    interp::Interpreter plain;
    rt::System a(test::compileModule(text), listing), b(test::compileModule(text), plain);
    for (int f = 0; f < 300; ++f) {
        REQUIRE_FALSE(a.step(1.0 / 60));
        REQUIRE_FALSE(b.step(1.0 / 60));
    }
    auto drop = static_cast<size_t>(a.typeIndex("drop"));
    CHECK(b.stats().types[drop].killed > 500);
    CHECK(a.stats().types[drop].killed == b.stats().types[drop].killed);
    CHECK(a.stats().types[drop].live == b.stats().types[drop].live);
}

TEST_CASE("each emission event creates `count` objects, all at the event's time") {
    Run run("object s { point(origin, white, age); }\nobject e { emit s at 2 per second count 3; }\nspawn e;");
    run.steps(300, 1.0 / 60);  // 5 s: events at 0.5 s, 1 s, …, 5 s
    CHECK(run.stats("s").created == 30);
    std::map<float, int> perAge;
    for (auto& p : run.points("s")) ++perAge[std::round(p.size * 1000) / 1000];
    CHECK(perAge.size() == 10);
    for (auto& [age, n] : perAge) CHECK(n == 3);
}

TEST_CASE("a render value that is a state value is drawn from the state column itself, not copied") {
    Run run("object a { pos = vec3(1, 2, 3) -> prev(pos) + vec3(0, dt, 0); point(pos, white, 2); }\n"
            "object b { pos = vec3(1, 2, 3) -> prev(pos) + vec3(0, dt, 0); point(pos + vec3(1, 0, 0), white, 2); }\n"
            "spawn a; spawn b;");
    run.steps(3, 1.0 / 60);
    for (std::string name : {"a", "b"}) {
        INFO(name);
        auto type = static_cast<size_t>(run.system->typeIndex(name));
        const ir::Object& o = run.system->module().objects[type];
        const rt::ColumnLayout layout = rt::columnLayout(o, *o.kernel(ir::KernelKind::Render));
        const rt::Pool& pool = run.system->pool(type);
        const rt::DrawColumns& drawn = run.system->draw(type);
        bool fromState = name == "a";
        for (int c = 0; c < 3; ++c) {
            int column = rt::ColumnLayout::kPosition + c;
            CHECK((layout.drawnFrom(column) == layout.stateOffset[0] + c) == fromState);
            CHECK(layout.needs(layout.render + column) == !fromState);  // no scratch column for it
            CHECK((drawn.position[static_cast<size_t>(c)] == pool.state.column(0, static_cast<size_t>(c))) == fromState);
        }
        // The colour and the size are constants: no column, the drawing hands over their values.
        for (int c = rt::ColumnLayout::kColor; c < rt::ColumnLayout::kRenderColumns; ++c) {
            CHECK(layout.constant(c).has_value());
            CHECK_FALSE(layout.needs(layout.render + c));
        }
        CHECK_FALSE(drawn.size.valid());
        CHECK(drawn.constant[7] == 2);
        auto points = run.points(name);
        REQUIRE(points.size() == 1);
        CHECK(points[0].position[0] == (fromState ? 1.0f : 2.0f));
        CHECK(points[0].position[1] == doctest::Approx(2.05f));
    }
}

TEST_CASE("the interpreter refuses an op it has no code for with the located internal error every backend gives") {
    interp::Interpreter interpreter;
    CHECK(test::refusal(interpreter) == test::expectedRefusal("the interpreter"));
}
