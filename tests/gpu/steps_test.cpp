// Sub-steps (@step) of types whose rows stay on the GPU (docs/gpu.md, "Sub-steps in the
// memory"): the memory's sub-step operations on the GPU against the same operations on
// the host (a batch's sub-step clocks, a kill list's rows cleared in the masks: written
// once in rt/memory.cpp and once in GLSL), such types against the interpreter object for
// object and row for row, and what a step of them moves between host and GPU as they grow.
#include <doctest/doctest.h>

#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "gpu_support.h"
#include "rt/clock.h"
#include "rt/memory.h"

using namespace psys;
using psys::test::gpuBackend;
using psys::test::readFile;

TEST_CASE("a batch's sub-step clocks, a kill list's cleared and gathered rows: the same bits on the GPU as on the host") {
    // Spans of no time, of exact multiples of @step, just past one, and at random, far
    // from the origin (where t1 − span rounds): each object's count of sub-steps, the end
    // of each and its length, with rows killed between sub-steps taken out and gathered
    // into one list (through a batch's rows, or from a base).
    auto gpu = gpuBackend();
    rt::HostMemory hostMemory;
    const double t1 = 12345.678 + 1.0 / 60, limit = 1.0 / 240;
    const size_t n = 3000, first = 7;
    std::vector<double> created(first + n, 0);
    std::vector<uint8_t> mask(first + n, 0);
    std::mt19937 random(5);
    std::uniform_real_distribution<double> span(0, 1.0 / 60);
    for (size_t r = 0; r < n; ++r) {
        double s = r % 5 == 0 ? limit * static_cast<double>(r % 4) : r % 5 == 1 ? limit * (1 + 1e-12) : span(random);
        created[first + r] = t1 - s;
        mask[first + r] = r % 11 != 3;
    }
    uint64_t capped = 0;
    const uint32_t most = rt::subStepCount(1.0 / 60, limit, capped);
    REQUIRE(most == 4);
    struct Columns {
        rt::Buffer created, mask, step, now, dt, killed, updatable, alive, map, gathered, length;
    };
    auto columnsOn = [&](rt::Memory& m) {
        Columns c{m.create(rt::Elem::F64, first + n), m.create(rt::Elem::U8, first + n), m.create(rt::Elem::U8, first + n),
                  m.create(rt::Elem::F64, first + n), m.create(rt::Elem::F32, first + n), m.create(rt::Elem::U32, n + 1),
                  m.create(rt::Elem::U8, first + n), m.create(rt::Elem::U8, first + n),
                  m.create(rt::Elem::U32, n), m.create(rt::Elem::U32, n + 1), m.create(rt::Elem::F64, first + n)};
        std::vector<uint32_t> through(n);
        for (uint32_t r = 0; r < n; ++r) through[r] = (r * 7919 + 5) % static_cast<uint32_t>(n);  // (a permutation)
        m.write(c.map, 0, n, through.data());
        m.fill(c.gathered, 0, 1, 0);
        m.write(c.created, 0, first + n, created.data());
        m.write(c.mask, 0, first + n, mask.data());
        std::vector<uint8_t> ones(first + n, 1);
        m.write(c.updatable, 0, first + n, ones.data());
        m.write(c.alive, 0, first + n, ones.data());
        return c;
    };
    Columns host = columnsOn(hostMemory), device = columnsOn(gpu->memory());
    size_t killedSoFar = 0;
    for (uint32_t k = 1; k <= most; ++k) {
        const bool wide = k % 2 == 1;  // (the unrounded lengths asked for, or not)
        hostMemory.subStepClocks(host.created, host.mask, host.step, host.now, host.dt, wide ? host.length : rt::Buffer{},
                                 first, n, k, most, t1, limit);
        gpu->memory().subStepClocks(device.created, device.mask, device.step, device.now, device.dt,
                                    wide ? device.length : rt::Buffer{}, first, n, k, most, t1, limit);
        std::vector<uint8_t> stepHost(n), stepDevice(n);
        std::vector<double> nowHost(n), nowDevice(n);
        std::vector<float> dtHost(n), dtDevice(n);
        hostMemory.read(host.step, first, n, stepHost.data());
        gpu->memory().read(device.step, first, n, stepDevice.data());
        hostMemory.read(host.now, first, n, nowHost.data());
        gpu->memory().read(device.now, first, n, nowDevice.data());
        hostMemory.read(host.dt, first, n, dtHost.data());
        gpu->memory().read(device.dt, first, n, dtDevice.data());
        INFO("sub-step " << k);
        REQUIRE(stepHost == stepDevice);
        CHECK(std::memcmp(nowHost.data(), nowDevice.data(), n * sizeof(double)) == 0);
        CHECK(std::memcmp(dtHost.data(), dtDevice.data(), n * sizeof(float)) == 0);
        if (wide) {
            std::vector<double> lengthHost(n), lengthDevice(n);
            hostMemory.read(host.length, first, n, lengthHost.data());
            gpu->memory().read(device.length, first, n, lengthDevice.data());
            CHECK(std::memcmp(lengthHost.data(), lengthDevice.data(), n * sizeof(double)) == 0);
            for (size_t r = 0; r < n; ++r)
                if (stepHost[r]) CHECK(static_cast<float>(lengthHost[r]) == dtHost[r]);
        }
        size_t stepped = 0;
        for (size_t r = 0; r < n; ++r) stepped += stepHost[r];
        CHECK(stepped > (k == 1 ? n / 2 : 10));
        // Every 7th stepped row killed: out of the step mask (launch rows from `first`) and
        // of the pool's masks (through no map: rows first + r).
        std::vector<uint32_t> list(1, 0);
        for (uint32_t r = 0; r < n; ++r)
            if (stepHost[r] && (r + k) % 7 == 0) list.push_back(r);
        list[0] = static_cast<uint32_t>(list.size() - 1);
        for (auto [m, c] : {std::pair<rt::Memory*, Columns*>{&hostMemory, &host}, {&gpu->memory(), &device}}) {
            m->write(c->killed, 0, list.size(), list.data());
            rt::PoolRows step, both;
            step.alive = c->step;
            both.updatable = c->updatable;
            both.alive = c->alive;
            m->clearRows(step, c->killed, 0, static_cast<uint32_t>(first), {}, 0);
            m->clearRows(both, c->killed, 0, static_cast<uint32_t>(first), {}, 0);
            if (k % 2)
                m->appendKills(c->killed, 0, static_cast<uint32_t>(first), {}, 0, c->gathered);
            else
                m->appendKills(c->killed, 0, 0, c->map, 0, c->gathered);
        }
        killedSoFar += list[0];
    }
    for (rt::Buffer Columns::*b : {&Columns::step, &Columns::updatable, &Columns::alive}) {
        std::vector<uint8_t> a(first + n), d(first + n);
        hostMemory.read(host.*b, 0, first + n, a.data());
        gpu->memory().read(device.*b, 0, first + n, d.data());
        CHECK(a == d);
    }
    std::vector<uint32_t> gatheredHost(n + 1), gatheredDevice(n + 1);
    hostMemory.read(host.gathered, 0, n + 1, gatheredHost.data());
    gpu->memory().read(device.gathered, 0, n + 1, gatheredDevice.data());
    CHECK(gatheredHost[0] == killedSoFar);
    CHECK(killedSoFar > 100);
    CHECK(gatheredHost == gatheredDevice);
    // (An object of no age takes one sub-step, ending at t1.)
    std::vector<double> now(n);
    hostMemory.read(host.now, first, n, now.data());
    CHECK(now[0] == t1);
}

TEST_CASE("objects in sub-steps keep their rows on the GPU: the interpreter's objects, rows and counts") {
    // tests/programs/step_sub_steps_in_the_memory.psys: drops that die between sub-steps
    // at a capacity that drops, from an emitter whose emissions the GPU decides; sparks
    // from a trigger fired mid-run; orbits that never die; comets' tails that read their
    // comet live and frozen, at each sub-step's clock.
    test::Pair p(readFile(test::programsDir() + "/step_sub_steps_in_the_memory.psys"));
    for (const char* type : {"drop", "spark", "orbit", "spout", "comet", "comet.tail"})
        CHECK(p.gl->pool(static_cast<size_t>(p.gl->typeIndex(type))).rowsInMemory());
    const float centre[] = {0, 1, 0};
    uint64_t frozen = 0;
    for (int f = 0; f < 150; ++f) {
        if (f == 10 || f == 70) {
            REQUIRE_FALSE(p.cpu->fire("flash", centre));
            REQUIRE_FALSE(p.gl->fire("flash", centre));
        }
        p.steps(1, 1.0 / 60);
        p.compare();
        frozen += p.stats("comet").frozen;
    }
    CHECK(p.stats("drop").dropped > 0);
    CHECK(p.stats("drop").killed > 300);
    CHECK(p.stats("spark").killed == 600);
    CHECK(p.stats("orbit").live == 50);
    CHECK(p.stats("comet").created == 6);  // (the launcher's 2 s at 3 a second)
    CHECK(frozen > 0);  // comets waited, frozen, for their tails
    CHECK(p.stats("comet.tail").killed > 200);
}

TEST_CASE("emitters in sub-steps decide their emissions on the GPU: the interpreter's objects, ids and rows") {
    // tests/programs/step_emitters_in_sub_steps.psys: fuses in sub-steps, each new one
    // through its own in its first update, emit drops at a rate that grows with their age,
    // in a burst at creation and on death, and die between sub-steps; crackers burst at
    // creation and die at once; a sprinkler and a flare that never die emit in sub-steps of
    // their own (the flare's sparks created after each); the drops' pool drops at capacity.
    test::Pair p(readFile(test::programsDir() + "/step_emitters_in_sub_steps.psys"));
    for (const char* type : {"drop", "fuse", "sprinkler", "launcher", "popper", "cracker", "flare", "spark", "pops"})
        CHECK(p.gl->pool(static_cast<size_t>(p.gl->typeIndex(type))).rowsInMemory());
    auto& gpu = *p.gpu;
    uint64_t waits = 0, hitch = 0;
    for (int f = 0; f < 150; ++f) {
        uint64_t before = gpu.waits();
        p.steps(1, f == 60 ? 0.25 : 1.0 / 60);  // (a hitch: 50 sub-steps of a fuse)
        (f == 60 ? hitch : waits) = std::max(f == 60 ? hitch : waits, gpu.waits() - before);
        p.compare();
    }
    CHECK(p.stats("drop").dropped > 0);
    CHECK(p.stats("fuse").created > 20);
    CHECK(p.stats("fuse").killed > 20);
    // A wait a sub-step of each emitter type, for its emissions' totals (docs/gpu.md).
    MESSAGE("emitters in sub-steps: at most " << waits << " waits a step at 1/60 s, " << hitch << " at a step of 0.25 s");
}

TEST_CASE("a fountain in sub-steps on the GPU: what a step moves and waits for does not grow with its drops") {
    // The fountain's drops under @step(1/240) (four sub-steps a frame): at 2,000 and at
    // 20,000 drops the same bytes a step, and one wait (the fountain's emissions' totals).
    auto perStep = [](float population) {
        auto gpu = gpuBackend();
        std::string text = readFile(test::sample("fountain"));
        size_t at = text.find("object drop(");
        REQUIRE(at != std::string::npos);
        text.insert(at, "@step(1 / 240)\n");
        rt::System system(test::compileModule(text), *gpu);
        REQUIRE(system.pool(static_cast<size_t>(system.typeIndex("drop"))).rowsInMemory());
        REQUIRE_FALSE(system.setExtern("population", std::vector<float>{population}));
        for (int f = 0; f < 200; ++f) REQUIRE_FALSE(system.step(1.0 / 60));
        CHECK(system.pool(static_cast<size_t>(system.typeIndex("drop"))).live() > population * 0.9);
        uint64_t before = gpu->transferredBytes(), waits = gpu->waits();
        for (int f = 0; f < 20; ++f) REQUIRE_FALSE(system.step(1.0 / 60));
        CHECK(gpu->waits() - waits == 20);
        return static_cast<double>(gpu->transferredBytes() - before) / 20;
    };
    double small = perStep(2000), large = perStep(20000);
    MESSAGE("fountain in sub-steps, bytes between host and GPU a step: " << small << " with 2,000 drops, " << large
                                                                          << " with 20,000");
    CHECK(large <= 1.1 * small + 8);
    CHECK(large < 1024);
}
