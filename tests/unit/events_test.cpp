// Bursts on events (docs/language.md, "Emitting"): a burst in a `when` fires where its
// condition becomes true, `on death` in the update that kills the object, with its last
// values — counted against exact answers on the interpreter (the backends are compared
// with it on the samples).
#include <doctest/doctest.h>

#include <cmath>

#include "run.h"

using namespace psys;
using test::Run;

TEST_CASE("a burst in a `when` fires once each time its condition becomes true") {
    // sin(2π·age) > 0.5 for age in (1/12, 5/12) of each second: one rising edge a second.
    Run run(R"(
        object c { point(origin, white, 1); }
        object o {
            s = sin(age * 6.2831853);
            when s > 0.5 { emit c count 2; }
            point(origin, white, 1);
        }
        spawn o;)");
    run.steps(4, 1.0 / 60);  // age 4/60 < 1/12: not yet
    CHECK(run.stats("c").created == 0);
    run.steps(26, 1.0 / 60);  // to 0.5 s: the first edge, and the condition still held after it
    CHECK(run.stats("c").created == 2);
    run.steps(150, 1.0 / 60);  // to 3 s: three edges
    CHECK(run.stats("c").created == 6);
}

TEST_CASE("a burst in a `when` that holds at creation fires then, and not again while it holds") {
    Run run(R"(
        object c { point(origin, white, age); }
        object o {
            when age < 1 { emit c count 5; }
            point(origin, white, 1);
        }
        spawn o;)");
    run.steps(1, 1.0 / 60);
    CHECK(run.stats("c").created == 5);
    run.steps(299, 1.0 / 60);
    CHECK(run.stats("c").created == 5);
}

TEST_CASE("`on death` bursts in the update that kills the object, with its last values, at that update's end") {
    Run run(R"(
        object c(p: vec3) { pos = snapshot(p); point(pos, white, age); }
        object o {
            pos = integrate(vec3(1, 0, 0));
            point(pos, white, 1);
            kill when age > 0.5;
            on death { emit c(pos) count 7; }
        }
        spawn o;)");
    run.steps(30, 1.0 / 60);  // age 0.5: alive
    CHECK(run.stats("c").created == 0);
    CHECK(run.points("o").size() == 1);
    run.steps(1, 1.0 / 60);  // age 31/60: killed, and its burst
    CHECK(run.points("o").empty());
    CHECK(run.stats("c").created == 7);
    auto c = run.points("c");
    REQUIRE(c.size() == 7);
    for (const rt::RenderPoint& p : c) {
        CHECK(p.position[0] == doctest::Approx(31.0 / 60).epsilon(1e-5));  // where the killing update left it
        CHECK(p.size == 0);                                                  // created at that update's end
    }
    run.steps(60, 1.0 / 60);
    CHECK(run.stats("c").created == 7);  // once
}

TEST_CASE("a burst in the `when` that kills fires: the firework's burst") {
    Run run(R"(
        object spark(p: vec3, v: vec3) { pos = snapshot(p) + integrate(snapshot(v)); point(pos, red, 1); }
        object rocket {
            pos = integrate(vel);
            vel = vec3(0, 10, 0) + integrate(vec3(0, -10, 0));
            point(pos, white, 1);
            when vel.y < 0 { emit spark(pos, nrand3() * 8) count 100; kill; }
        }
        spawn rocket;)");
    run.steps(120, 1.0 / 60);
    CHECK(run.stats("rocket").killed == 1);
    CHECK(run.stats("spark").created == 100);
}

TEST_CASE("a rate emitter creates nothing in the update that kills it, its `on death` does") {
    Run run(R"(
        object c { point(origin, white, 1); }
        object o {
            emit c at 60 per second;
            kill when age > 0.25;
            on death { emit c count 1000; }
        }
        spawn o;)");
    run.steps(60, 1.0 / 60);
    // updates at 1/60 … 15/60 emit one each (15), the 16th kills: no rate, the burst
    CHECK(run.stats("c").created == 15 + 1000);
}

TEST_CASE("objects that die in their first update burst too, also in sub-steps") {
    for (const char* step : {"", "@step(1/240)"}) {
        CAPTURE(step);
        Run run(std::string(R"(
            object c { point(origin, white, 1); kill when age > 0.1; }
            )") + step + R"( object o {
                kill when age > 0;
                on death { emit c count 3; }
            }
            object e { emit o at 120 per second; }
            spawn e;)");
        run.steps(60, 1.0 / 60);
        CHECK(run.stats("o").created == 120);
        CHECK(run.stats("o").killed == 119);  // (the last, created at the step's end, is 0 s old)
        CHECK(run.stats("c").created == 3 * 119);
    }
}

TEST_CASE("bursts on events are the same with one thread and with several") {
    std::string text = R"(
        object c(p: vec3) { pos = snapshot(p) + integrate(nrand3()); point(pos, white, 1); kill when age > 0.3; }
        object o {
            pos = integrate(nrand3() * 4);
            point(pos, white, 1);
            when pos.y > 0.5 { emit c(pos) count 4; }
            kill when age > 0.2 + rand();
            on death { emit c(pos) count 9; }
        }
        object e { emit o at 3000 per second; }
        spawn e;)";
    rt::SystemOptions one, many;
    one.threads = 1;
    many.threads = 4;
    Run a(text, one), b(text, many);
    CHECK(test::compareRuns(a, b, 90, test::bitwise) > 1000);
}
