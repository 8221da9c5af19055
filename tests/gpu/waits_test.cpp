// What the host waits for on the GPU: a step waits only for what it decides by (and, with
// the emitters on the host side, for nothing); late kills are taken at the next step, and
// what is drawn before leaves them out.
#include <doctest/doctest.h>

#include "gpu_support.h"

using namespace psys;
using namespace psys::test;

// (Not in the suite `long`: CI runs it under the sanitizers, as many frames as each
// sample's types need; 600 frames of drift on the GPU are gpu_test.cpp's every-sample sweep's.)
TEST_CASE("with small pools run on the host, every sample draws what the interpreter draws, for 600 frames") {
    // The emitters (a launcher, a comet, rockets: few rows, their columns on the host) run
    // on the host side; their particles on the GPU, reading them (spawns, parents' exports)
    // from the host's copies.
    for (const auto& path : test::sweptSamples()) {
        INFO(path.filename().string());
        std::string text = readFile(path);
        test::Comparison c = compareProgram(text, test::sweepFrames(text), true, kSamplesTolerance, true);
        CHECK(c.points > 0);
    }
}

TEST_CASE("a small pool on the host that outgrows the host side moves to the GPU, and computes the same") {
    // Emitters created 30 a second, living 4 s: past 64 rows after about 2 s. Their update
    // (they emit and die: the step must know which) runs on the host while the pool is
    // small, then on the GPU once a launch has put its columns there; never back.
    Pair p(R"(
        object launcher {
            emit burster(vec3(nrand(), 0, nrand())) at 30 per second;
        }
        object burster(start: vec3) {
            pos = snapshot(start) + integrate(vec3(0, 1, 0));
            point(pos, white, 2);
            emit ember(pos) at 20 + 10 * sin(age * 3) per second;
            kill when age > 4;
        }
        object ember(from: vec3) {
            pos = snapshot(from) + integrate(vel);
            vel = snapshot(nrand3());
            point(pos, red, 1);
            kill when age > 0.5;
        }
        spawn launcher;)",
           true, true);
    auto waitsOver = [&](int frames) {
        uint64_t before = p.gpu->waits(), host = p.gpu->hostLaunches();
        for (int f = 0; f < frames; ++f) {
            p.steps(1, 1.0 / 60);
            for (size_t t = 0; t < p.gl->typeCount(); ++t) p.gl->draw(t);
            p.gl->stats();
        }
        return std::pair{p.gpu->waits() - before, p.gpu->hostLaunches() - host};
    };
    auto [smallWaits, smallHost] = waitsOver(60);  // at most 31 bursters
    CHECK(smallWaits == 0);
    CHECK(smallHost >= 60 * 2);  // the launcher's and the bursters' updates, at least
    p.compare();
    waitsOver(120);  // 120 bursters
    auto [bigWaits, bigHost] = waitsOver(10);
    CHECK(bigWaits >= 10);  // the bursters' update, on the GPU
    CHECK(bigHost < 10 * 3);
    p.compare();
    for (int f = 0; f < 60; ++f) {
        p.steps(1, 1.0 / 60);
        if (f % 10 == 0) p.compare();
    }
}

TEST_CASE("a pool of objects that never die, kept in the memory, frees nothing at a step's end") {
    // Found by the program generator: 40 objects on the host side, then 40 more created in
    // one step (bursts of 20 from a nested emitter) take the pool past 64 rows, onto the
    // GPU. The update there said it had listed its kills for the step's end, though its
    // kernel kills nothing and listed none: the end of the step freed what a reused list
    // still held, and 20 live objects were no longer drawn.
    Pair p(R"(
        object t0 {
            pos = vec3(0.219, 0.603, 0.647) + vec3(age * 1.954, age * -1.656, 0);
            emit n1 at 3 per second;
            object n1 { emit t2 at 40 per second count 20; }
        }
        object t2 {
            pos = snapshot(vec3(-0.807, -0.046, 0.799)) + integrate(vel);
            vel = snapshot(nrand3() * 1.799) + integrate(vec3(0, -6.847, 0) - vel * 1.282);
            streak(pos - vel * 0.03, pos, white, 0.036);
        }
        spawn t0;)",
           true, true);
    for (int f = 0; f < 20; ++f) {
        p.steps(1, 1.0 / 30);
        p.compare();
    }
}

TEST_CASE("the host waits for the GPU mid-step only for what the step decides by, however many rows and emitters") {
    // With no host side, every launch on the GPU: what a step must read back at once is
    // the totals of each operation that decides emissions (Memory::emitAtRate: what its
    // emitters asked for and kept, which size the batches it creates), one wait each —
    // the fountain's, once a step; the launcher's and the rockets' each step, and the
    // first update of a batch of new rockets. Not a launch per 8192 rows, not a read per
    // value of each emitter's row for its children's arguments, not the children's
    // arguments, not a column of new objects' state to zero it; not the kills of objects
    // whose dead nobody reads during the step (drops, sparks: taken at its end); not a
    // draw's counts (taken when the stats ask for them). (With the host side, the
    // emitters' few rows are on the host and no step waits: the next test.)
    struct Waits {  // over 10 steps
        uint64_t step, late, draw;
    };
    auto waitsPerStep = [](const std::string& sample, const char* knob, float value) {
        auto gpu = gpuBackend();
        rt::System system(test::compileModule(readFile(test::sample(sample))), *gpu);
        if (knob) REQUIRE_FALSE(system.setExtern(knob, {&value, 1}));
        for (int f = 0; f < 200; ++f) {  // past 3 s: the drops' pool has stopped growing
            REQUIRE_FALSE(system.step(1.0 / 60));
            for (size_t t = 0; t < system.module().objects.size(); ++t) system.draw(t);
            system.stats();
        }
        // Late read-backs are taken when the run-time needs them, or by stats() once the GPU
        // has them ready: how many fall in a window of steps depends on the GPU's speed,
        // unless what is owed is taken at both ends (finish(): a wait).
        system.finish();
        Waits w{0, 0, 0};
        uint64_t early = gpu->lateEarly();
        for (int f = 0; f < 10; ++f) {
            uint64_t before = gpu->waits(), late = gpu->lateReads();
            REQUIRE_FALSE(system.step(1.0 / 60));
            w.step += gpu->waits() - before;
            w.late += gpu->lateReads() - late;
            before = gpu->waits();
            late = gpu->lateReads();
            for (size_t t = 0; t < system.module().objects.size(); ++t) system.draw(t);
            w.draw += gpu->waits() - before;
            system.stats();  // takes the draws' counts
            w.late += gpu->lateReads() - late;
        }
        uint64_t late = gpu->lateReads();
        system.finish();
        w.late += gpu->lateReads() - late;
        // The read-back buffer has grown to what a step keeps in it: no late launch is
        // read before the run-time asks for it.
        INFO(sample);
        CHECK(gpu->lateEarly() == early);
        return w;
    };
    // 60,000 drops: 8 chunks of 8192 rows on a CPU.
    Waits fountain = waitsPerStep("fountain", "population", 60000);
    // 15 rockets emitting sparks every step, each its own spawn launch.
    Waits fireworks = waitsPerStep("fireworks", "sparks", 200);
    MESSAGE("over 10 steps and draws, waits mid-step, read-backs taken late, waits for draws: fountain " << fountain.step << ", "
            << fountain.late << ", " << fountain.draw << "; fireworks " << fireworks.step << ", " << fireworks.late
            << ", " << fireworks.draw);
    CHECK(fountain.step == 10);
    CHECK(fountain.late == 30);  // the drops' update, the new drops' first update, the draw
    CHECK(fountain.draw == 0);
    CHECK(fireworks.step <= 22);  // (a rocket every sixth step: 2 batches in 10 steps)
    CHECK(fireworks.draw == 0);
    // An update whose only answer is its count of updates past the stability limit (the
    // wind's `- vel`: a decay rate): a counter, taken at the step's end.
    Waits wind = waitsPerStep("wind", nullptr, 0);
    CHECK(wind.step == 0);
    CHECK(wind.late == 20);
    // Children reading their parent's exports live (the comet's tail): the values are
    // gathered on the GPU, for the update and for the draw. What remains is the comet's
    // update, once a step: it emits and may die.
    Waits comet = waitsPerStep("follow_parent", nullptr, 0);
    MESSAGE("follow_parent: " << comet.step << ", " << comet.late << ", " << comet.draw);
    CHECK(comet.step <= 10);
    CHECK(comet.draw == 0);
}

TEST_CASE("with the emitters on the host, a step waits for the GPU never, and the particles stay on the GPU") {
    // What remained of the waits: emitters that may die (the rockets, the comet) or that
    // each have their own rate (the emitter's sine): a few rows, run by the host side.
    auto run = [](const std::string& sample) {
        auto gpu = gpuBackend(true);
        rt::System system(test::compileModule(readFile(test::sample(sample))), *gpu);
        for (int f = 0; f < 200; ++f) {
            REQUIRE_FALSE(system.step(1.0 / 60));
            for (size_t t = 0; t < system.module().objects.size(); ++t) system.draw(t);
            system.stats();
        }
        system.finish();  // what is owed taken at both ends: a count that does not depend on the GPU's speed
        uint64_t waits = gpu->waits(), late = gpu->lateReads(), host = gpu->hostLaunches();
        for (int f = 0; f < 10; ++f) {
            REQUIRE_FALSE(system.step(1.0 / 60));
            for (size_t t = 0; t < system.module().objects.size(); ++t) system.draw(t);
            system.stats();
        }
        INFO(sample);
        CHECK(gpu->waits() == waits);
        system.finish();
        CHECK(gpu->hostLaunches() > host);
        return gpu->lateReads() - late;
    };
    // The particles' updates and the draws of pools past the host side's 64 rows still on the
    // GPU: the fountain's drops' update and draw, 2 a step (a step's 17 new drops, a batch
    // of 17 rows, run their first update on the host side); the fireworks' sparks and the
    // emitter's particles. The comet's tail, fewer than 64, runs on the host altogether.
    CHECK(run("fireworks") >= 20);
    // The fire's new particles, a batch of a few rows a step that the host side runs, some
    // dying in their first update: cleared in the alive mask through the batch's row list
    // on the GPU (GlMemory::clearMapped), not read back for it.
    CHECK(run("fire") >= 10);
    CHECK(run("follow_parent") == 0);
    CHECK(run("emitter") >= 20);
    CHECK(run("fountain") == 20);
}

TEST_CASE("emitters on the host side decide their emissions there: the rain's clouds wait for nothing") {
    // 40 clouds (rows on the host side) emit drops by the memory's operation, which runs
    // where the clouds' rows are — their records and totals on the host, read without a
    // wait, whatever GPU buffer the operation's scratch was before — and only the clouds'
    // records go up for the new drops' ids. What waits is the drops' own operation, twice a
    // step: over the pool's thousands of rows, and over the step's ~107 new drops (past the
    // host side's 64), which burst on death.
    // The objects are the interpreter's throughout.
    std::string text = readFile(test::sample("rain"));
    for (int i = 1; i < 40; ++i) text += "\nspawn cloud;";
    Pair p(text, true, true);
    p.steps(120, 1.0 / 60);
    const rt::Pool& clouds = p.gl->pool(static_cast<size_t>(p.gl->typeIndex("cloud")));
    const rt::Pool& drops = p.gl->pool(static_cast<size_t>(p.gl->typeIndex("drop")));
    REQUIRE(clouds.rowsInMemory());
    REQUIRE(drops.rowsInMemory());
    REQUIRE(drops.live() > 3000);
    CHECK(p.compare() <= kSamplesTolerance);
    uint64_t waits = p.gpu->waits(), bytes = p.gpu->transferredBytes();
    for (int f = 0; f < 10; ++f) REQUIRE_FALSE(p.gl->step(1.0 / 60));
    double perStep = static_cast<double>(p.gpu->transferredBytes() - bytes) / 10;
    MESSAGE("the rain with 40 clouds: " << p.gpu->waits() - waits << " waits in 10 steps, " << perStep
                                        << " bytes a step between host and GPU");
    CHECK(p.gpu->waits() - waits == 20);
    CHECK(perStep < 16384);  // (the drops' records, were they sent: 72 bytes a drop)
    for (int f = 0; f < 10; ++f) REQUIRE_FALSE(p.cpu->step(1.0 / 60));
    p.steps(30, 1.0 / 60);
    CHECK(p.compare() <= kSamplesTolerance);
}

TEST_CASE("a step's late kills are taken at the next step — what is drawn before leaves them out") {
    // Flashes die in their first update (they live 1 ms; a step is 16.7), drops in a later
    // one: the GPU clears their rows in the alive mask the draws read, and the host takes
    // the kills — freeing the rows, in the interpreter's order — when the next step starts
    // (or stats() finds them ready, or finish()). Without the clearing, the points drawn
    // after a step would include the dead. A hundred flashes a step and 150 drops: pools and
    // batches past the host side's 64 rows, on the GPU with the host side too.
    for (bool hostSide : {false, true}) {
        INFO("host side " << hostSide);
        Pair p(R"(
            object source {
                emit flash at 6000 per second;
                emit drop at 600 per second;
            }
            object flash {
                point(vec3(age, 1, 0), white, 1);
                kill when age > 0.001;
            }
            object drop {
                pos = integrate(vec3(0, 1, 0));
                point(pos, red, 1);
                kill when age > 0.25;
            }
            spawn source;)",
               true, hostSide);
        bool owed = false;
        for (int f = 0; f < 90; ++f) {
            p.steps(1, 1.0 / 60);
            // Taken late: the host's pools still count the step's dead (they are alive
            // until the kills are taken).
            for (size_t t = 0; t < p.cpu->typeCount(); ++t) owed |= p.gl->pool(t).live() != p.cpu->pool(t).live();
            p.compare();
            REQUIRE(test::poolRows(*p.cpu) == test::poolRows(*p.gl));
        }
        CHECK(owed);
        CHECK(p.gl->stats().types.at(static_cast<size_t>(p.gl->typeIndex("flash"))).killed > 100);
    }
}
