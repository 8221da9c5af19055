// The end of a system and a type's box (docs/runtime.md, "Host API"): finished() when
// nothing is alive and nothing waits to be created, the host's callback once each time;
// bounds() the box around the points a type draws.
#include <doctest/doctest.h>

#include <algorithm>
#include <limits>

#include "run.h"

using namespace psys;
using test::Run;

TEST_CASE("a system is finished when nothing is alive and nothing waits to be created, and a trigger revives it") {
    int calls = 0;
    rt::SystemOptions options;
    options.onFinished = [&](const rt::System& s) {
        ++calls;
        CHECK(s.finished());
    };
    Run run(R"(
        object p { point(origin, white, 1); kill when age > 0.5; }
        object e { emit p count 3; kill when age > 0.2; }
        trigger again { emit p count 2; }
        spawn e;)", options);
    CHECK_FALSE(run.system->finished());  // not started
    int steps = 0;
    while (!run.system->finished() && steps < 100) {
        run.steps(1, 1.0 / 60);
        ++steps;
    }
    CHECK(steps == 31);  // the burst's objects die in the update at age 31/60 > 0.5
    CHECK(calls == 1);
    run.steps(5, 1.0 / 60);
    CHECK(calls == 1);  // once: it stays finished
    REQUIRE_FALSE(run.system->fire("again", {}));
    CHECK_FALSE(run.system->finished());
    run.steps(40, 1.0 / 60);
    CHECK(run.system->finished());
    CHECK(calls == 2);
}

TEST_CASE("a system that keeps something alive, or keeps emitting, is never finished") {
    for (const char* text : {"object p { point(origin, white, 1); }\nspawn p;",
                             "object p { point(origin, white, 1); kill when age > 0.1; }\n"
                             "object e { point(origin, white, 1); emit p at 10 per second; }\nspawn e;"}) {
        Run run(text);
        run.steps(300, 1.0 / 60);
        CHECK_FALSE(run.system->finished());
    }
}

TEST_CASE("a type's box is the box of the points it draws, on every sample") {
    for (const std::string& text : test::samplesAndPrograms()) {
        Run run(text);
        run.steps(90, 1.0 / 60);
        for (size_t t = 0; t < run.system->typeCount(); ++t) {
            auto points = run.system->points(t);
            rt::Bounds box = run.system->bounds(t);
            INFO(run.system->module().objects[t].name);
            REQUIRE(box.empty == points.empty());
            for (size_t c = 0; c < 3; ++c) {
                float lo = std::numeric_limits<float>::infinity(), hi = -lo;
                for (const auto& p : points) {
                    lo = std::min(lo, p.position[c]);
                    hi = std::max(hi, p.position[c]);
                }
                if (points.empty()) continue;
                CHECK(box.low[c] == lo);
                CHECK(box.high[c] == hi);
            }
        }
    }
}
