// The schedule of a step (rt/schedule.h): the phases follow from what each type's kernels
// yield, in the module's order, and the printed form names them.
#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "interp/interpreter.h"
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
    // Every phase on every thread: updates in chunks, the bookkeeping in pieces; late kills
    // are only handed to the ledger (the host's: no rows).
    CHECK(s.phases[2].parallelism == rt::Parallelism::Chunks);
    CHECK(s.phases[3].parallelism == rt::Parallelism::Host);
    for (size_t p : {0, 1, 6, 7, 8, 9}) CHECK(s.phases[p].parallelism == rt::Parallelism::Pieces);
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

TEST_CASE("the schedule says which types keep their rows in the memory, and where they are freed") {
    // The fountain's drops only die: with their rows in the memory, their kills are listed
    // there and freed there at the step's end. The fountain never dies and emits them at
    // a rate: where rows are kept in the memory wherever they can be, its rows are there
    // too and its emissions the memory's operation (Memory::emitAtRate).
    std::string text = test::readFile(std::string(PSYS_SAMPLES_DIR) + "/fountain.psys");
    const rt::SystemOptions options = test::rowsInMemory();
    interp::Interpreter backend, other;
    rt::System kept(test::compileModule(text), backend, options), plain(test::compileModule(text), other);
    const rt::Schedule& s = kept.schedule();
    REQUIRE(s.inMemory.size() == 2);
    CHECK(s.inMemory[static_cast<size_t>(kept.typeIndex("drop"))]);
    CHECK(s.inMemory[static_cast<size_t>(kept.typeIndex("fountain"))]);
    CHECK(kept.pool(static_cast<size_t>(kept.typeIndex("drop"))).rowsInMemory());
    std::string printed = rt::printSchedule(s);
    CHECK(printed.find("its kills listed in the memory") != std::string::npos);
    CHECK(printed.find("drop: the kill lists kept for the step's end, where the memory frees them") != std::string::npos);
    CHECK(printed.find("(drop: rows, ids and creation times by the memory's operations)") != std::string::npos);
    CHECK(printed.find("drop: the kill lists freed in the memory") != std::string::npos);
    CHECK(printed.find("fountain: the update kernel over the pool, its rows in the memory") != std::string::npos);
    CHECK(printed.find("fountain: rate emissions (drop) decided by the memory's operation") != std::string::npos);
    CHECK(printed.find("each target's objects one run, each site's spawn launches one launch, from the records") !=
          std::string::npos);
    CHECK(rt::printSchedule(plain.schedule()).find("memory") == std::string::npos);  // the interpreter's own choice: the host
    // The rain's drops die and burst on death into types that only die: their rows, kills
    // and bursts in the memory too; and so the cloud, which emits them at a rate.
    rt::System rain(test::compileModule(test::readFile(std::string(PSYS_SAMPLES_DIR) + "/rain.psys")), backend, options);
    CHECK(rain.pool(static_cast<size_t>(rain.typeIndex("drop"))).rowsInMemory());
    CHECK(rain.pool(static_cast<size_t>(rain.typeIndex("cloud"))).rowsInMemory());
    printed = rt::printSchedule(rain.schedule());
    CHECK(printed.find("cloud: rate emissions (drop) decided by the memory's operation") != std::string::npos);
    CHECK(printed.find("drop: the kill lists kept for the step's end, where the memory frees them") != std::string::npos);
    CHECK(printed.find("drop: rate emissions of the survivors, bursts on edges and deaths (droplet, ripple) decided by the "
                       "memory's operation") != std::string::npos);
    // The fireworks' rockets burst and die on an edge: their bursts (at creation too) and
    // the launcher's rate emissions of them, the memory's.
    rt::System fireworks(test::compileModule(test::readFile(std::string(PSYS_SAMPLES_DIR) + "/fireworks.psys")), backend,
                         options);
    CHECK(fireworks.pool(static_cast<size_t>(fireworks.typeIndex("rocket"))).rowsInMemory());
    CHECK(fireworks.pool(static_cast<size_t>(fireworks.typeIndex("launcher"))).rowsInMemory());
    CHECK(rt::printSchedule(fireworks.schedule()).find("rocket: rate emissions of the survivors, bursts on edges and deaths "
                                                       "(spark, star) decided by the memory's operation") != std::string::npos);
    // The shapes' four sites into `mote` share its room: one operation still.
    rt::System shapes(test::compileModule(test::readFile(std::string(PSYS_SAMPLES_DIR) + "/shapes.psys")), backend, options);
    CHECK(shapes.pool(static_cast<size_t>(shapes.typeIndex("shapes"))).rowsInMemory());
    CHECK(rt::printSchedule(shapes.schedule()).find("shapes: rate emissions (mote, spark, mote, mote, mote) decided by the "
                                                    "memory's operation") != std::string::npos);
    // Drops in sub-steps keep their rows in the memory: each sub-step's kills listed there
    // (an earlier one's taken out of the masks at once); so does their emitter in
    // sub-steps, its emissions the memory's each sub-step, and one whose children read it,
    // beside them, and one in sub-steps whose arguments read its parent's age (gathered
    // at each new one's own sub-step ends: Creation::agesAtSubStep).
    rt::System stepped(test::compileModule("@step(1/240) object d { point(vec3(age), white, 1); kill when age > rand(); }\n"
                                           "@step(1/240) object e { emit d at 100 per second; }\nspawn e;"),
                       backend, options);
    CHECK(stepped.pool(static_cast<size_t>(stepped.typeIndex("d"))).rowsInMemory());
    CHECK(stepped.pool(static_cast<size_t>(stepped.typeIndex("e"))).rowsInMemory());
    rt::System read(test::compileModule("@step(1/240) object c { pos = vec3(age); emit t at 50 per second;\n"
                                        "object t { point(c.pos, white, 1); kill when age > 0.2; } }\nspawn c;"),
                    backend, options);
    CHECK(read.pool(static_cast<size_t>(read.typeIndex("c"))).rowsInMemory());
    CHECK(read.pool(static_cast<size_t>(read.typeIndex("c.t"))).rowsInMemory());
    rt::System args(test::compileModule("object p { pos = vec3(age); emit c at 5 per second;\n"
                                        "  @step(1/240) object c { emit d(vec3(p.age)) at 50 per second; } }\n"
                                        "object d(x: vec3) { point(x, white, 1); kill when age > 0.2; }\nspawn p;"),
                    backend, options);
    CHECK(args.pool(static_cast<size_t>(args.typeIndex("p.c"))).rowsInMemory());
    CHECK(args.pool(static_cast<size_t>(args.typeIndex("d"))).rowsInMemory());
    printed = rt::printSchedule(stepped.schedule());
    CHECK(printed.find("d: the next 2 phases once per sub-step") != std::string::npos);
    CHECK(printed.find("  update     chunks on every thread   d: the update kernel over the pool, its kills listed in "
                       "the memory") != std::string::npos);
    CHECK(printed.find("d: the kill lists kept for the step's end, where the memory frees them; an earlier sub-step's "
                       "taken out of the masks there at once") != std::string::npos);
    CHECK(printed.find("  emissions  in the memory            e: rate emissions (d) decided by the memory's operation") !=
          std::string::npos);
    // An emitter of two types of emitters: the memory decides its emissions too (a
    // generation's batches go type by type wherever its runs were decided).
    rt::System two(test::compileModule(test::readFile(std::string(PSYS_PROGRAMS_DIR) + "/two_kinds_of_emitter_from_one.psys")),
                   backend, options);
    for (const char* type : {"e", "a", "b"}) CHECK(two.pool(static_cast<size_t>(two.typeIndex(type))).rowsInMemory());
    CHECK(rt::printSchedule(two.schedule()).find("e: rate emissions (b, a) decided by the memory's operation") !=std::string::npos);
}

TEST_CASE("a new object's first update has dt its age at the step's end, computed by the backend — sub-steps under @step, per-row columns") {
    using S = rt::Clock::Source;
    for (bool step : {false, true}) {
        std::string text = std::string(step ? "@step(0.004) " : "") +
                           "object p { x = integrate(1); point(vec3(x, age, 0), white, 1); kill when age > 0.3; }\n"
                           "object e { emit p at 500 per second; }\nspawn e;";
        // The clocks of the update launches over creation batches (their clock is per row).
        std::vector<std::pair<S, S>> clocks;
        test::WatchedInterpreter backend([&](const rt::RowsLaunch& l) {
            if (l.kernel->kind == ir::KernelKind::Update && l.clock.perRow()) clocks.push_back({l.clock.now, l.clock.dt});
        });
        rt::System system(test::compileModule(text), backend);
        for (int f = 0; f < 10; ++f) REQUIRE_FALSE(system.step(1.0 / 60));
        REQUIRE_FALSE(clocks.empty());
        size_t subStepped = 0;  // batches where some object needs more than one sub-step
        for (auto [now, dt] : clocks) {
            bool since = now == S::Uniform && dt == S::SinceCreated, columns = now == S::PerRow && dt == S::PerRow;
            CHECK((since || (step && columns)));
            subStepped += columns;
        }
        CHECK((subStepped > 0) == step);
        // The values are those of the rule: x = age for every object, created at any time.
        auto type = static_cast<size_t>(system.typeIndex("p"));
        std::vector<rt::RenderPoint> points = system.points(type);
        REQUIRE(points.size() > 50);
        for (const rt::RenderPoint& p : points) CHECK(p.position[0] == doctest::Approx(p.position[1]).epsilon(1e-5));
    }
}

TEST_CASE("under @step the printed schedule says what runs: only the last sub-step's kills are kept for the step's end") {
    // The motes only die and nobody reads them: their kills are late — in the last of the
    // step's 4 sub-steps; an earlier sub-step's dead are taken at once (the next sub-step
    // must not update them).
    std::string text = R"(
        @step(0.005) object mote { x = integrate(1); point(vec3(x), white, 1); kill when age > 0.05 + 0.2 * rand(); }
        object e { emit mote count 50; }
        spawn e;)";
    // Whether each update launch over the motes' pool (a uniform clock: not a creation's) was late.
    std::string seen;
    test::WatchedInterpreter backend([&](const rt::RowsLaunch& l) {
        if (l.object->name == "mote" && l.kernel->kind == ir::KernelKind::Update &&
            l.clock.now == rt::Clock::Source::Uniform && l.clock.dt == rt::Clock::Source::Uniform && l.begin == 0)
            seen += l.late ? "L" : ".";
    });
    rt::System system(test::compileModule(text), backend);
    const rt::Schedule& s = system.schedule();
    auto kills = std::find_if(s.phases.begin(), s.phases.end(), [&](const rt::Phase& p) {
        return p.kind == rt::PhaseKind::Kills && s.types[static_cast<size_t>(p.type)] == "mote";
    });
    REQUIRE(kills != s.phases.end());
    CHECK(kills->late);
    CHECK(rt::printSchedule(s).find("mote: the last sub-step's listed kills kept for the step's end (nobody looks at "
                                    "them before); an earlier sub-step's killed rows frozen at once") != std::string::npos);
    for (int f = 0; f < 3; ++f) REQUIRE_FALSE(system.step(1.0 / 60));
    // The motes are created at the start; each step updates them in 4 sub-steps.
    CHECK(seen == "...L...L...L");
}
