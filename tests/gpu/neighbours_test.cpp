// Neighbour folds on the GPU (gpu/gl_fold.cpp): the grid built and walked there, the
// results where the update reads them — no wait for the GPU, nothing read back — and the
// interpreter's folds within tolerance; every fold, over its own type and another, with
// deaths that free rows new objects take (tests/programs/neighbours.psys); two types that
// fold over each other (tests/programs/mutual_folds.psys).
#include <doctest/doctest.h>

#include "gpu_support.h"

using namespace psys;
using namespace psys::test;

TEST_CASE("a crowd's folds on the GPU add no wait to a step") {
    // The beads of repel.psys once poured (after 2 s): nothing dies or is created, so a
    // step decides nothing by what the GPU computes, and waits for nothing.
    Pair p(readFile(test::sample("repel")));
    p.steps(150, 1.0 / 60);
    REQUIRE(p.stats("bead").live == 800);
    uint64_t waits = p.gpu->waits(), moved = p.gpu->transferredBytes();
    REQUIRE_FALSE(p.gl->step(1.0 / 60));
    for (int f = 0; f < 10; ++f) REQUIRE_FALSE(p.gl->step(1.0 / 60));
    CHECK(p.gpu->waits() == waits);
    uint64_t perStep = (p.gpu->transferredBytes() - moved) / 11;
    MESSAGE(perStep << " bytes a step between host and GPU for 800 beads");
}

TEST_CASE("every fold on the GPU, over its own type and another, with deaths and rows taken again, gives the interpreter's") {
    Pair p(readFile(programsDir() + "/neighbours.psys"));
    p.steps(60, 1.0 / 60);  // 80 grains by then, past the host side's few rows; 20 frames of them folded on the GPU
    REQUIRE(p.stats("grain").live > 64);
    CHECK(p.compare() <= kSamplesTolerance);
    p.steps(240, 1.0 / 60);  // deaths (at 3 s) and rows taken again: then the same objects, in the same rows
    p.compare();
}

TEST_CASE("two types folding over each other on the GPU, each reading the other's folds, give the interpreter's") {
    // tests/programs/mutual_folds.psys: mice that flee the cats declared after them, cats
    // that chase them and read their fold (`other.fear`). A crowd: compared over its first
    // frames (test::kCrowdRun), its folds on the GPU once past the host side's few rows.
    Pair p(readFile(programsDir() + "/mutual_folds.psys"));
    for (int frame = 0; frame < test::kCrowdRun; ++frame) {
        p.steps(1, 1.0 / 60);
        CHECK(p.compare() <= kSamplesTolerance);
    }
    CHECK(p.stats("mouse").live > 40);
    CHECK(p.stats("cat").live == 3);
}

TEST_CASE("a fold's grid on the GPU is the same every run: its buckets' rows sorted after the atomics scatter them") {
    // 2,000 beads made at once, pushing each other apart: no object is created or dies
    // after the first step, so what could differ between two runs is the folds' order.
    const char* crowd = R"(
        object bead(ipos: vec3) {
            push = near_sum(bead, 0.3, (pos - other.pos) * (0.3 - distance(pos, other.pos)));
            vel = vec3(0) -> prev(vel) * 0.95 + push * (60 * dt);
            pos = ipos -> prev(pos) + vel * dt;
            point(pos, vec4(near_count(bead, 0.3) / 20, 0, 0, 1), 1);
        }
        object pile { emit bead(rand3() * 2) count 2000; kill when age > 0; }
        spawn pile;)";
    auto run = [&] {
        auto gpu = gpuBackend(false);
        rt::System system(test::compileModule(crowd), *gpu);
        return test::drawnBytes(system, 90);
    };
    CHECK(run() == run());
}

TEST_CASE("a flock that never dies keeps its rows on the GPU: created there, folded there, what a step moves does not grow with it") {
    // Birds that fold over each other and never die: their pool's rows, masks and exports
    // stay on the GPU, and an object created in the step folds over nothing (the same
    // empty folds the interpreter gives it) — birds joining at a rate, compared with the
    // interpreter; then flocks of 2,000 and 20,000 made at once.
    const char* flock = R"(
        object bird(ipos: vec3) {
            mates = near_count(bird, 0.6);
            centre = near_sum(bird, 0.6, other.pos);
            nearest = near_min(bird, 0.6, distance(pos, other.pos));
            vel = vec3(0.2, 0, 0) -> prev(vel) * 0.9 + (mates > 0 ? centre / mates - pos : vec3(0)) * dt;
            pos = ipos -> prev(pos) + vel * dt;
            point(pos, vec4(mates / 10, min(nearest, 1), 0, 1), 1);
        }
        object sky { emit bird(rand3() * SPREAD) at RATE per second; emit bird(rand3() * SPREAD) count COUNT; }
        spawn sky;)";
    auto program = [&](int rate, int count, int spread) {
        std::string text = flock;
        for (int i = 0; i < 2; ++i) text.replace(text.find("SPREAD"), 6, std::to_string(spread));
        text.replace(text.find("RATE"), 4, std::to_string(rate));
        text.replace(text.find("COUNT"), 5, std::to_string(count));
        return text;
    };
    Pair p(program(600, 0, 3));
    p.steps(30, 1.0 / 60);  // 300 birds by then, past the host side's few rows
    CHECK(p.gl->pool(static_cast<size_t>(p.gl->typeIndex("bird"))).rowsInMemory());
    CHECK(p.compare() <= kSamplesTolerance);
    p.steps(30, 1.0 / 60);
    CHECK(p.compare() <= kSamplesTolerance);

    auto perStep = [&](int birds) {
        auto gpu = gpuBackend();
        // (spread out: a few neighbours each, so that the folds cost little at 20,000)
        rt::System system(test::compileModule(program(0, birds, 40)), *gpu);
        for (int f = 0; f < 5; ++f) REQUIRE_FALSE(system.step(1.0 / 60));
        CHECK(system.pool(static_cast<size_t>(system.typeIndex("bird"))).live() == static_cast<size_t>(birds));
        uint64_t before = gpu->transferredBytes(), waits = gpu->waits();
        for (int f = 0; f < 10; ++f) REQUIRE_FALSE(system.step(1.0 / 60));
        // One a step, however many birds: the sky's emissions' totals (its row on the GPU,
        // with no host side), not the folds'.
        CHECK(gpu->waits() - waits == 10);
        return static_cast<double>(gpu->transferredBytes() - before) / 10;
    };
    double small = perStep(2000), large = perStep(20000);
    MESSAGE("bytes between host and GPU a step: " << small << " with 2,000 birds, " << large << " with 20,000");
    CHECK(large <= small + 8);
    CHECK(large < 256);
}
