// Inputs at and past the limits a user or a generated program can reach: each ends in a
// documented outcome (a clamp that is counted, an error value, correct behaviour), never
// a crash, a hang, an overflow or a silent wrong value.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <functional>

#include "run.h"

using namespace psys;
using test::Run;

TEST_CASE("counts and rates past 1e18 are taken as 1e18 and counted — dropped stops at 2^64 - 1") {
    SUBCASE("a count of 1e30 per event") {
        Run run("@capacity(100) object b { point(origin, white, 1); }\n"
                "object e { emit b at 1 per second count 1e30; }\nspawn e;");
        run.steps(90, 1.0 / 60);
        CHECK(run.stats("b").live == 100);
        CHECK(run.system->stats().clampedEmissions == 1);
        CHECK(run.stats("b").dropped == 1'000'000'000'000'000'000ull - 100);
    }
    SUBCASE("a trigger's count from its argument") {
        Run run("@capacity(10) object b { point(origin, white, 1); }\ntrigger t(n: float) { emit b count n; }");
        float n = 1e30f;
        REQUIRE_FALSE(run.system->fire("t", {&n, 1}));
        run.steps(1, 1.0 / 60);
        CHECK(run.stats("b").live == 10);
        CHECK(run.system->stats().clampedEmissions == 1);
        CHECK(run.stats("b").dropped == 1'000'000'000'000'000'000ull - 10);
    }
    SUBCASE("a rate of 1e30 for 120 frames") {
        Run run("@capacity(10) object b { point(origin, white, 1); }\nobject e { emit b at 1e30 per second; }\nspawn e;");
        uint64_t last = 0;
        for (int f = 0; f < 120; ++f) {
            run.steps(1, 1.0 / 60);
            CHECK(run.stats("b").dropped >= last);  // never wraps around
            last = run.stats("b").dropped;
        }
        CHECK(last == UINT64_MAX);
        CHECK(run.system->stats().clampedEmissions >= 120);
    }
    SUBCASE("a burst at creation of 1e30") {
        Run run("@capacity(5) object b { point(origin, white, 1); }\nobject e { emit b count 1e30; }\nspawn e;");
        run.steps(1, 1.0 / 60);
        CHECK(run.stats("b").live == 5);
        CHECK(run.system->stats().clampedEmissions == 1);
    }
}

TEST_CASE("@step sub-steps are capped at 10,000 an update, and counted") {
    SUBCASE("@step(1e-30)") {
        Run run("@step(1e-30) object a { pos = integrate(vec3(1)); point(pos, white, 1); }\nspawn a;");
        run.steps(2, 1.0 / 60);
        CHECK(run.stats("a").cappedSubSteps == 2);  // the first update at creation, then one step
        CHECK(run.points("a")[0].position[0] == doctest::Approx(2.0 / 60));
    }
    SUBCASE("@step(1/240) and a step of 1e9 s") {
        Run run("@step(1/240) object a { pos = integrate(vec3(1)); point(pos, white, 1); }\nspawn a;");
        run.steps(1, 1.0 / 60);
        run.steps(1, 1e9);  // (a step past 2^32 s is refused: docs/runtime.md, "Time")
        CHECK(run.stats("a").cappedSubSteps == 1);
        CHECK(run.stats("a").live == 1);
    }
    SUBCASE("rows in the memory: a batch's objects counted as the host counts them") {
        // (The memory steps each new object through its own sub-steps: Memory::subStepClocks;
        // past the cap the host reads their creation times back to count them.)
        const char* text = "@step(1e-7) object a { pos = integrate(vec3(1)); point(pos, white, 1); kill when age > 3e-3; }\n"
                           "object e { emit a at 2000 per second; }\nspawn e;";
        Run host(text), memory(text, test::rowsInMemory());
        REQUIRE(memory.system->pool(memory.type("a")).rowsInMemory());
        for (int f = 0; f < 3; ++f) {
            host.steps(1, 1.0 / 400);
            memory.steps(1, 1.0 / 400);
            CHECK(memory.stats("a").cappedSubSteps == host.stats("a").cappedSubSteps);
            CHECK(memory.stats("a").killed == host.stats("a").killed);
            CHECK(test::poolRows(*memory.system) == test::poolRows(*host.system));
        }
        CHECK(host.stats("a").cappedSubSteps > 3);
        CHECK(host.stats("a").killed > 0);
    }
    SUBCASE("a 10 s hitch at @step(1/240) is 2,400 sub-steps: not capped") {
        Run run("@step(1/240) object a { pos = integrate(vec3(1)); point(pos, white, 1); }\nspawn a;");
        run.steps(1, 10.0);
        CHECK(run.stats("a").cappedSubSteps == 0);
    }
}

namespace {

// `text` on the host and with its rows in the memory (type `kept` there), through two
// frames and a 3 s hitch: after each step `same` compares them; returns the bytes the
// memory grew by in the hitch (the first steps make the pools).
size_t hitchGrowth(const char* text, const char* kept, const std::function<void(Run&, Run&)>& same) {
    Run host(text), memory(text, test::rowsInMemory());
    REQUIRE(memory.system->pool(memory.type(kept)).rowsInMemory());
    auto& bytes = dynamic_cast<rt::HostMemory&>(memory.backend.memory());
    size_t growth = 0;
    for (double dt : {1.0 / 60, 1.0 / 60, 3.0}) {
        size_t before = bytes.bytes();
        host.steps(1, dt);
        memory.steps(1, dt);
        growth = bytes.bytes() > before ? bytes.bytes() - before : 0;
        same(host, memory);
        CHECK(test::poolRows(*memory.system) == test::poolRows(*host.system));
    }
    return growth;
}

}  // namespace

TEST_CASE("a hitch of hundreds of sub-steps, rows in the memory: the kills gathered into one list, not one a sub-step") {
    // 20,000 objects through 720 sub-steps of one 3 s step, most dying between them: each
    // sub-step's kill list is gathered into the step's (Ledger::takeOut) and goes back to
    // the pool for the next — without, 720 lists of 20,000 rows (58 MB).
    uint64_t killed = 0;
    size_t growth = hitchGrowth(
        "@step(1/240) object a { pos = integrate(vec3(1)); point(pos, white, 1); kill when age > rand() * 4; }\n"
        "object e { emit a count 20000; }\nspawn e;",
        "a", [&](Run& host, Run& memory) {
            CHECK(memory.stats("a").killed == host.stats("a").killed);
            killed = host.stats("a").killed;
        });
    CHECK(growth < 20000 * 4 * 4);
    CHECK(killed > 10000);
}

TEST_CASE("a hitch of hundreds of sub-steps of emitters in the memory: each sub-step's records go with its objects") {
    // 2,000 emitters through 720 sub-steps of one 3 s step: each sub-step's emissions are
    // records of every emitter row (Memory::emitAtRate), and what it queued is created after
    // it (rt/schedule.cpp) — without, 720 sub-steps' records held to the step's end (52 MB).
    uint64_t drops = 0, emittersKilled = 0;
    size_t growth = hitchGrowth(
        "@capacity(20000) object d { point(vec3(age), white, 1); kill when age > 0.1; }\n"
        "@step(1/240) object s { emit d at 2 per second; kill when age > 2 + rand() * 4; }\n"
        "object l { emit s count 2000; kill; }\nspawn l;",
        "s", [&](Run& host, Run& memory) {
            for (const char* type : {"d", "s"}) {
                CHECK(memory.stats(type).created == host.stats(type).created);
                CHECK(memory.stats(type).killed == host.stats(type).killed);
            }
            drops = host.stats("d").created;
            emittersKilled = host.stats("s").killed;
        });
    CHECK(growth < (size_t{1} << 20));
    CHECK(drops > 10000);
    CHECK(emittersKilled > 500);
}

// A tuple's state is its elements' state: each program below runs bit for bit as the same
// equations written one element at a time.
TEST_CASE("tuples through prev, snapshot, -> and ?: are composite state") {
    struct Case {
        const char* tuple;
        const char* elements;
    };
    const Case cases[] = {
        {"object o { (p, q) = prev((age, 2)); point(vec3(p, q, 0), white, 1); }",
         "object o { p = prev(age); q = prev(2); point(vec3(p, q, 0), white, 1); }"},
        {"fn two(x: float) -> (float, float) = (x + 1, x * 2);\n"
         "object o { (p, q) = snapshot(two(age + 0.5)); point(vec3(p, q, age), white, 1); }",
         "object o { p = snapshot(age + 0.5 + 1); q = snapshot((age + 0.5) * 2); point(vec3(p, q, age), white, 1); }"},
        {"object o { c = age > 0.05; (p, q) = prev(c ? (1, 2) : (3, 4)); point(vec3(p, q, 0), white, 1); }",
         "object o { c = age > 0.05; p = prev(c ? 1 : 3); q = prev(c ? 2 : 4); point(vec3(p, q, 0), white, 1); }"},
        {"object o { (p, q) = (1, 2) -> prev((p + 1, q * 2)); point(vec3(p, q, 0), white, 1); }",
         "object o { p = 1 -> prev(p + 1); q = 2 -> prev(q * 2); point(vec3(p, q, 0), white, 1); }"},
        {"object o { (p, q) = (vec3(1), 2) -> prev((p * 2, q + 1)); point(p, white, q); }",
         "object o { p = vec3(1) -> prev(p * 2); q = 2 -> prev(q + 1); point(p, white, q); }"},
    };
    for (const Case& c : cases) {
        CAPTURE(c.tuple);
        Run tuple(std::string(c.tuple) + "\nspawn o;"), elements(std::string(c.elements) + "\nspawn o;");
        CHECK(test::compareRuns(tuple, elements, 30, test::bitwise) == 30);
    }
}

TEST_CASE("min, max and clamp on NaN and signed zeros are symmetric, at run time and folded") {
    std::string text = test::readFile(PSYS_PROGRAMS_DIR "/nan_edges.psys");
    for (bool optimize : {false, true}) {
        CAPTURE(optimize);
        Run run(text, {}, optimize);
        run.steps(2, 1.0 / 60);
        auto points = run.points("o");
        REQUIRE(points.size() == 2);  // nothing is NaN
        for (const rt::RenderPoint& p : points) {
            float k = p.size - 1;
            CHECK(p.position[0] == 4 * k);  // max(NaN, k) + max(k, NaN), run and folded
            CHECK(p.position[1] == 4 * k);
            CHECK(p.position[2] == 0);      // clamp(NaN) and saturate(NaN): 0
            const float pi = std::atan2(0.0f, -1.0f);
            CHECK(p.color == std::array<float, 4>{-pi, -pi, pi, pi});  // min is -0, max is +0, either order
        }
    }
}

TEST_CASE("a frozen parent's age is frozen with its other values") {
    Run run(R"(
        object parent {
            x = age;
            emit child count 1;
            kill when age > 1;
            object child { point(vec3(parent.x, parent.age, parent.alive ? 1 : 0), white, 1); }
        }
        spawn parent;)");
    run.steps(4, 0.25);
    CHECK(run.points("parent.child")[0].position[1] == doctest::Approx(1.0));
    run.steps(5, 0.25);  // dead at the update to 1.25: its last values are those at age 1
    const auto& c = run.points("parent.child");
    REQUIRE(c.size() == 1);
    CHECK(c[0].position[0] == doctest::Approx(1.0));
    CHECK(c[0].position[1] == doctest::Approx(1.0));  // not 2.25: age does not go on rising
    CHECK(c[0].position[2] == 0);
}

TEST_CASE("a pool filling up inside its steps moves none of its columns or host arrays: each has its capacity's room") {
    // Without the room (Pool::reserveRows) every column and host array doubles as the rows
    // pass its size, copied inside the step that needs the rows: a 0.2 ms step of the fire
    // at 10^5 a second took 6 ms at 500,000 rows (`psys_bench --hitches`).
    for (bool inMemory : {false, true}) {
        CAPTURE(inMemory);
        rt::SystemOptions options = inMemory ? test::rowsInMemory() : rt::SystemOptions{};
        options.capacity = 60000;
        Run run("object b(v: vec3) { pos = integrate(v); point(pos, white, 1); }\n"
                "object e { emit b(nrand3()) at 100000 per second; }\nspawn e;",
                options);
        run.steps(1, 1.0 / 60);
        const rt::Pool& pool = run.system->pool(run.type("b"));
        REQUIRE(pool.room() == 60000);
        rt::Memory& memory = run.backend.memory();
        auto where = [&] {
            std::vector<const void*> at = {rt::hostData<double>(memory, pool.created), rt::hostData<uint32_t>(memory, pool.ids),
                                           pool.updatable.host(), pool.alive.host(),
                                           rt::hostData<float>(memory, pool.state.column(0, 0)),
                                           rt::hostData<float>(memory, pool.params.column(0, 2)),
                                           pool.parent.data(), pool.readers.data(), pool.diedAt.data()};
            if (!inMemory) at.push_back(pool.generations().data());
            return at;
        };
        std::vector<const void*> before = where();
        size_t rows = pool.rows();
        run.steps(40, 1.0 / 60);
        CHECK(pool.rows() > 30 * rows);
        CHECK(pool.live() == 60000);
        CHECK(where() == before);
    }
}
