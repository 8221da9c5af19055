// The schedule of a step (rt/schedule.h): the phases follow from what each type's kernels
// yield, in the module's order, and the printed form names them.
#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "run.h"

using namespace psys;

namespace {

// The phases as "kind type" words, sub-step groups as "sub-steps(N)".
std::vector<std::string> phases(const rt::Schedule& s) {
    std::vector<std::string> out;
    for (const rt::Phase& p : s.phases) {
        std::string word = rt::phaseName(p.kind);
        if (p.kind == rt::PhaseKind::SubSteps) word += "(" + std::to_string(p.span) + ")";
        if (p.type >= 0) word += " " + s.types[static_cast<size_t>(p.type)];
        out.push_back(word);
    }
    return out;
}

}  // namespace

TEST_CASE("a step's schedule has a phase for what each type does, and none for what it does not") {
    test::Run run(R"(
        object spark { point(vec3(age), white, 1); kill when age > 1; }
        object still { point(vec3(0), white, 1); }
        object rocket {
            emit spark at 100 per second;
            kill when age > 2;
        }
        spawn rocket;
        spawn still;)");
    const rt::Schedule& s = run.system->schedule();
    std::vector<std::string> expected = {"settle",         "ready",           "update spark", "kills spark",
                                         "update still",   "update rocket",   "kills rocket", "emissions rocket",
                                         "create rocket",  "release"};
    CHECK(phases(s) == expected);
    // The spark's dead nobody looks at before the step's end: taken there (LateKills).
    CHECK(s.phases[3].late);
    CHECK(s.phases[3].listed);
    // The rocket emits: its kills come from the kill flags, in row order, before it emits.
    CHECK_FALSE(s.phases[6].late);
    CHECK(s.phases[8].targets == std::vector<int>{0});
    CHECK(s.phases[2].parallelism == rt::Parallelism::Chunks);
    CHECK(s.phases[7].parallelism == rt::Parallelism::Ordered);
}

TEST_CASE("under @step a type's update, kills and emissions repeat per sub-step — its creation does not") {
    test::Run run(R"(
        object mote { point(vec3(age), white, 1); }
        @step(0.005) object ball {
            pos = integrate(vec3(1, 0, 0));
            emit mote at 10 per second;
            kill when age > 5;
        }
        spawn ball;)");
    const rt::Schedule& s = run.system->schedule();
    std::vector<std::string> expected = {"settle",       "ready",          "update mote",  "sub-steps(3) ball",
                                         "update ball",  "kills ball",     "emissions ball", "create ball",
                                         "release"};
    CHECK(phases(s) == expected);
    CHECK(s.phases[3].stepLimit == doctest::Approx(0.005));
    std::string text = rt::printSchedule(s);
    CHECK(text.find("  4. sub-steps") != std::string::npos);
    CHECK(text.find("  5.   update") != std::string::npos);  // indented inside the group
    CHECK(text.find("  8. create") != std::string::npos);     // not inside it
    CHECK(text.find("@step(0.005)") != std::string::npos);
    // The sub-steps run: 1/60 s at @step(0.005) is 4 sub-steps, each an update of the ball.
    run.steps(1, 1.0 / 60);
    run.steps(1, 1.0 / 60);
    CHECK(run.stats("ball").live == 1);
}
