// A pool's rows kept on the GPU (rt::Pool::keepRowsInMemory): the memory's row operations
// on the GPU against the same operations on the host (the allocation rule, the release of a
// kill list, the fresh rows, ids and creation times from runs, written once for the host in
// rt/memory.cpp and once in GLSL in gpu/gl_rows.cpp), and what a step of a pool kept there
// moves between the host and the GPU as its objects grow.
#include <doctest/doctest.h>

#include <algorithm>
#include <numeric>
#include <cstring>
#include <random>
#include <vector>

#include "gpu_support.h"
#include "rt/clock.h"
#include "rt/memory.h"

using namespace psys;
using psys::test::gpuBackend;
using psys::test::readFile;

namespace {

// A pool's rows on one memory: the buffers the operations change, and the host's counts.
struct Rows {
    rt::Memory& memory;
    rt::PoolRows rows;
    rt::Buffer out, killed, map;
    explicit Rows(rt::Memory& m, size_t n) : memory(m) {
        rows = {m.create(rt::Elem::U32, n), m.create(rt::Elem::U32, n), m.create(rt::Elem::U8, n),
                m.create(rt::Elem::U8, n), m.create(rt::Elem::U32, rt::kCounters), m.create(rt::Elem::U32, n),
                m.create(rt::Elem::U8, n), {}, {}};
        out = m.create(rt::Elem::U32, n);
        killed = m.create(rt::Elem::U32, n + 1);
        map = m.create(rt::Elem::U32, n);
    }
    template <typename T>
    std::vector<T> read(rt::Buffer b, size_t n) const {
        std::vector<T> v(n);
        memory.read(b, 0, n, v.data());
        return v;
    }
};

}  // namespace

TEST_CASE("the memory's row operations compute on the GPU what they compute on the host") {
    // Batches allocated from the stack and past the high-water mark, kill lists released
    // through a batch's row list and at a base, the fresh rows marked: the stacks,
    // generations, masks and row lists of the two memories agree after every operation.
    auto gpu = gpuBackend();
    rt::HostMemory hostMemory;
    constexpr size_t kRows = 5000;
    Rows host(hostMemory, kRows), device(gpu->memory(), kRows);
    std::mt19937 random(7);
    size_t top = 0, highWater = 0, live = 0;
    std::vector<uint32_t> alive;  // the rows alive, host side
    for (int round = 0; round < 60; ++round) {
        INFO("round " << round);
        // A batch of n objects: rows by the allocation rule.
        size_t room = top + (kRows - highWater);
        size_t n = std::min<size_t>(room, random() % 400);
        for (Rows* r : {&host, &device}) r->memory.allocateRows(r->rows, top, highWater, n, r->out, 0);
        std::vector<uint32_t> batch = host.read<uint32_t>(host.out, n);
        REQUIRE(batch == device.read<uint32_t>(device.out, n));
        size_t fromStack = std::min(n, top);
        highWater += n - fromStack;
        top -= fromStack;
        live += n;
        alive.insert(alive.end(), batch.begin(), batch.end());
        // Some die: a kill list of launch rows over a batch's row list, or at a base.
        std::vector<uint32_t> list{0};
        bool mapped = round % 2 == 1 && n > 0;
        if (mapped) {
            for (Rows* r : {&host, &device}) r->memory.write(r->map, 0, n, batch.data());
            for (uint32_t k = 0; k < n; ++k)
                if (random() % 3 == 0) list.push_back(k);
        } else {
            std::shuffle(alive.begin(), alive.end(), random);
            std::vector<uint32_t> dying(alive.begin(), alive.begin() + static_cast<std::ptrdiff_t>(alive.size() / 4));
            std::sort(dying.begin(), dying.end());
            for (uint32_t row : dying) list.push_back(row - 3);  // launch rows from a base of 3
        }
        list[0] = static_cast<uint32_t>(list.size() - 1);
        for (Rows* r : {&host, &device}) {
            r->memory.write(r->killed, 0, list.size(), list.data());
            r->memory.releaseRows(r->rows, r->killed, 0, 3, mapped ? r->map : rt::Buffer{}, 0);
        }
        std::vector<uint32_t> freed;
        for (size_t i = 1; i < list.size(); ++i) freed.push_back(mapped ? batch[list[i]] : list[i] + 3);
        std::erase_if(alive, [&](uint32_t row) { return std::find(freed.begin(), freed.end(), row) != freed.end(); });
        top += freed.size();
        live -= freed.size();
        // The batch's survivors become updatable.
        if (round % 3 == 0) {
            for (Rows* r : {&host, &device}) {
                r->memory.write(r->map, 0, n, batch.data());
                r->memory.markFresh(r->rows, r->map, 0, n);
            }
        }
        REQUIRE(host.read<uint32_t>(host.rows.counters, 1) == device.read<uint32_t>(device.rows.counters, 1));
        REQUIRE(host.read<uint32_t>(host.rows.counters, 1)[0] == top);
        REQUIRE(host.read<uint32_t>(host.rows.stack, top) == device.read<uint32_t>(device.rows.stack, top));
        REQUIRE(host.read<uint32_t>(host.rows.generation, highWater) ==
                device.read<uint32_t>(device.rows.generation, highWater));
        REQUIRE(host.read<uint8_t>(host.rows.alive, highWater) == device.read<uint8_t>(device.rows.alive, highWater));
        REQUIRE(host.read<uint8_t>(host.rows.updatable, highWater) ==
                device.read<uint8_t>(device.rows.updatable, highWater));
        auto aliveMask = host.read<uint8_t>(host.rows.alive, highWater);
        REQUIRE(static_cast<size_t>(std::count(aliveMask.begin(), aliveMask.end(), 1)) == live);
    }
    CHECK(highWater > 1000);
    CHECK(top > 100);
}

TEST_CASE("parents and their readers: the GPU frees and freezes the rows the host does, in its order") {
    // Parents with random children; children die, their parents' readers counted down;
    // parents die, the unread freed in the kill list's order and the read frozen; frozen
    // parents whose children all went freed in row order. The parents are children too
    // (PoolRows::parents): each freed a reader less of its own parent. Both memories,
    // after each.
    auto gpu = gpuBackend();
    rt::HostMemory hostMemory;
    constexpr size_t kParents = 3000, kChildren = 9000, kGrandparents = 400;
    Rows host(hostMemory, kParents), device(gpu->memory(), kParents);
    std::mt19937 random(11);
    std::vector<uint32_t> parentOf(kChildren), readers(kParents, 0), grandparentOf(kParents), grandReaders(kGrandparents, 0);
    for (uint32_t& p : parentOf) {
        p = random() % 5 == 0 ? rt::kSkipRow : static_cast<uint32_t>(random() % kParents);
        if (p != rt::kSkipRow) ++readers[p];
    }
    for (uint32_t& g : grandparentOf) {
        g = random() % 7 == 0 ? rt::kSkipRow : static_cast<uint32_t>(random() % kGrandparents);
        if (g != rt::kSkipRow) ++grandReaders[g];
    }
    rt::Buffer parents[2];
    int which = 0;
    for (Rows* r : {&host, &device}) {
        r->memory.allocateRows(r->rows, 0, 0, kParents, r->out, 0);
        r->memory.write(r->rows.readers, 0, kParents, readers.data());
        parents[which] = r->memory.create(rt::Elem::U32, kChildren);
        r->memory.write(parents[which++], 0, kChildren, parentOf.data());
        r->rows.parents = r->memory.create(rt::Elem::U32, kParents);
        r->memory.write(r->rows.parents, 0, kParents, grandparentOf.data());
        r->rows.parentReaders = r->memory.create(rt::Elem::U32, kGrandparents);
        r->memory.write(r->rows.parentReaders, 0, kGrandparents, grandReaders.data());
    }
    auto same = [&](const char* what) {
        INFO(what);
        REQUIRE(host.read<uint32_t>(host.rows.counters, rt::kCounters) ==
                device.read<uint32_t>(device.rows.counters, rt::kCounters));
        uint32_t top = host.read<uint32_t>(host.rows.counters, 1)[0];
        REQUIRE(host.read<uint32_t>(host.rows.stack, top) == device.read<uint32_t>(device.rows.stack, top));
        REQUIRE(host.read<uint32_t>(host.rows.generation, kParents) == device.read<uint32_t>(device.rows.generation, kParents));
        REQUIRE(host.read<uint32_t>(host.rows.readers, kParents) == device.read<uint32_t>(device.rows.readers, kParents));
        REQUIRE(host.read<uint8_t>(host.rows.waiting, kParents) == device.read<uint8_t>(device.rows.waiting, kParents));
        REQUIRE(host.read<uint8_t>(host.rows.alive, kParents) == device.read<uint8_t>(device.rows.alive, kParents));
        REQUIRE(host.read<uint8_t>(host.rows.updatable, kParents) ==
                device.read<uint8_t>(device.rows.updatable, kParents));
        REQUIRE(host.read<uint32_t>(host.rows.parentReaders, kGrandparents) ==
                device.read<uint32_t>(device.rows.parentReaders, kGrandparents));
    };
    std::vector<uint32_t> childrenAlive(kChildren), parentsAlive(kParents);
    std::iota(childrenAlive.begin(), childrenAlive.end(), 0u);
    std::iota(parentsAlive.begin(), parentsAlive.end(), 0u);
    for (int round = 0; round < 12; ++round) {
        INFO("round " << round);
        // Children die (a list at a base of 0): their parents' readers counted down.
        std::shuffle(childrenAlive.begin(), childrenAlive.end(), random);
        size_t dying = childrenAlive.size() / 3;
        std::vector<uint32_t> list{static_cast<uint32_t>(dying)};
        list.insert(list.end(), childrenAlive.end() - static_cast<std::ptrdiff_t>(dying), childrenAlive.end());
        childrenAlive.resize(childrenAlive.size() - dying);
        which = 0;
        for (Rows* r : {&host, &device}) {
            r->memory.write(r->killed, 0, list.size(), list.data());
            r->memory.readersGone(r->killed, 0, 0, {}, 0, parents[which++], r->rows.readers);
        }
        same("children gone");
        // Parents die, in a shuffled order: the unread pushed in it, the read frozen.
        std::shuffle(parentsAlive.begin(), parentsAlive.end(), random);
        dying = std::min<size_t>(parentsAlive.size(), 150 + random() % 200);
        list.assign(1, static_cast<uint32_t>(dying));
        for (size_t i = parentsAlive.size() - dying; i < parentsAlive.size(); ++i) list.push_back(parentsAlive[i]);
        parentsAlive.resize(parentsAlive.size() - dying);
        for (Rows* r : {&host, &device}) {
            r->memory.write(r->killed, 0, list.size(), list.data());
            r->memory.releaseUnread(r->rows, r->killed, 0, 0, {}, 0);
        }
        same("parents released or frozen");
        for (Rows* r : {&host, &device}) r->memory.releaseWaiting(r->rows, kParents);
        same("frozen parents without readers freed");
    }
    auto counters = host.read<uint32_t>(host.rows.counters, rt::kCounters);
    CHECK(counters[0] > 1000);  // freed,
    CHECK(counters[1] > 50);    // and still frozen for their children
    // Each freed parent (on the stack) a reader less of its own parent, no other.
    std::vector<uint32_t> expected = grandReaders;
    for (uint32_t row : host.read<uint32_t>(host.rows.stack, counters[0]))
        if (grandparentOf[row] != rt::kSkipRow) --expected[grandparentOf[row]];
    CHECK(host.read<uint32_t>(host.rows.parentReaders, kGrandparents) == expected);
}

TEST_CASE("ids and creation times from a batch's runs: the same bits on the GPU as on the host") {
    // Runs of one object, of many at once, of events apart (perEvent objects each), one of
    // none; times that round differently if a product and a sum were fused.
    auto gpu = gpuBackend();
    rt::HostMemory hostMemory;
    rt::ObjectRuns runs;
    auto add = [&](uint32_t count, uint32_t id, uint32_t perEvent, double firstTime, double spacing) {
        runs.first.push_back(runs.first.empty() ? 0 : runs.first.back() + runs.count.back());
        runs.count.push_back(count);
        runs.id.push_back(id);
        runs.perEvent.push_back(perEvent);
        runs.firstTime.push_back(firstTime);
        runs.spacing.push_back(spacing);
    };
    add(1, 10, 1, 0.1, 0);
    add(700, 11, 1, 1.0 / 3, 1.0 / 7000);
    add(0, 711, 1, 2, 1);
    add(300, 711, 7, 12345.678, 0.1 / 3);
    add(50, 1011, 50, 1e7 + 1.0 / 3, 0);
    size_t n = runs.first.back() + runs.count.back(), kept = n - 20, first = 5;
    std::vector<double> created[2];
    std::vector<uint32_t> ids[2];
    std::vector<uint8_t> mask[2];
    int which = 0;
    for (rt::Memory* m : {static_cast<rt::Memory*>(&hostMemory), &gpu->memory()}) {
        rt::Buffer c = m->create(rt::Elem::F64, first + n), i = m->create(rt::Elem::U32, first + n),
                   k = m->create(rt::Elem::U8, first + n);
        m->identify(runs, n, kept, c, i, k, first);
        created[which].resize(n);
        ids[which].resize(n);
        mask[which].resize(n);
        m->read(c, first, n, created[which].data());
        m->read(i, first, n, ids[which].data());
        m->read(k, first, n, mask[which].data());
        ++which;
    }
    CHECK(std::memcmp(created[0].data(), created[1].data(), n * sizeof(double)) == 0);
    CHECK(ids[0] == ids[1]);
    CHECK(mask[0] == mask[1]);
    CHECK(ids[0][1] == 11);
    CHECK(ids[0][n - 1] == 1011 + 49);
    CHECK(created[0][701 + 14] == rt::eventTime(12345.678, 14, 7, 0.1 / 3));
    CHECK(mask[0][kept - 1] == 1);
    CHECK(mask[0][kept] == 0);
}

TEST_CASE("a scatter of several columns by a row list moves on the GPU what it moves on the host") {
    // Nine pairs of columns (more than a dispatch takes: GlMemory::kScatterColumns) of
    // every element type, by a list of distinct rows with skipped ones, from a batch's row
    // 7 on: the targets' rows the list names get the batch's values, the others keep theirs.
    auto gpu = gpuBackend();
    rt::HostMemory hostMemory;
    constexpr size_t kCount = 300, kRows = 1000, kFirst = 7;
    const std::vector<rt::Elem> elems = {rt::Elem::F32, rt::Elem::F64, rt::Elem::U32, rt::Elem::U8, rt::Elem::F32,
                                         rt::Elem::F32, rt::Elem::F64, rt::Elem::U8,  rt::Elem::F32};
    std::mt19937 random(11);
    std::vector<uint32_t> rows(kRows), list(kCount), identity(kCount);
    for (uint32_t r = 0; r < kRows; ++r) rows[r] = r;
    std::shuffle(rows.begin(), rows.end(), random);
    for (uint32_t i = 0; i < kCount; ++i) {
        list[i] = i % 13 == 0 ? rt::kSkipRow : rows[i];
        identity[i] = i;
    }
    std::vector<std::vector<uint8_t>> values(2 * elems.size());  // from, to: random bytes
    for (size_t c = 0; c < elems.size(); ++c) {
        values[2 * c].resize((kFirst + kCount) * rt::elemSize(elems[c]));
        values[2 * c + 1].resize(kRows * rt::elemSize(elems[c]));
        for (auto* v : {&values[2 * c], &values[2 * c + 1]})
            for (uint8_t& b : *v) b = static_cast<uint8_t>(random() % 200);  // (no NaN's payload to lose)
    }
    std::vector<std::vector<uint8_t>> after[2];
    int which = 0;
    for (rt::Memory* m : {static_cast<rt::Memory*>(&hostMemory), &gpu->memory()}) {
        // The list where a device's operations leave it (on the GPU: scattered there).
        rt::Buffer staged = m->create(rt::Elem::U32, kCount), listed = m->create(rt::Elem::U32, kCount);
        m->write(staged, 0, kCount, list.data());
        m->scatter(staged, 0, listed, identity);
        std::vector<std::pair<rt::Buffer, rt::Buffer>> columns;
        for (size_t c = 0; c < elems.size(); ++c) {
            rt::Buffer from = m->create(elems[c], kFirst + kCount), to = m->create(elems[c], kRows);
            m->write(from, 0, kFirst + kCount, values[2 * c].data());
            m->write(to, 0, kRows, values[2 * c + 1].data());
            columns.push_back({from, to});
        }
        uint64_t dispatches = gpu->dispatches();
        m->scatter(columns, kFirst, listed, 0, kCount);
        if (which == 1) CHECK(gpu->dispatches() - dispatches == 2);  // seven pairs, then two
        for (size_t c = 0; c < elems.size(); ++c) {
            after[which].emplace_back(kRows * rt::elemSize(elems[c]));
            m->read(columns[c].second, 0, kRows, after[which].back().data());
        }
        ++which;
    }
    for (size_t c = 0; c < elems.size(); ++c) {
        INFO("column " << c);
        CHECK(after[0][c] == after[1][c]);
        CHECK(after[0][c] != values[2 * c + 1]);  // it moved something
    }
}

TEST_CASE("a creation batch zeroes only the state its init does not set, and runs no init that sets nothing") {
    // The fountain's init sets every slot of a drop's state: its batches clear nothing.
    // The fire's sets the velocity, not the two integrals, which start at zero: six
    // components cleared a batch (and the objects are the interpreter's: gpu_test.cpp).
    // The fireworks' sparks start with their integrals at zero: their init is empty and
    // does not run (the rockets' sets their velocity: a launch for each rocket's batch).
    auto passes = [](const char* effect, const char* pass) {
        auto gpu = gpuBackend();
        rt::System system(test::compileModule(readFile(test::sample(effect))), *gpu);
        for (int f = 0; f < 30; ++f) REQUIRE_FALSE(system.step(1.0 / 60));
        gpu->timePasses(true);
        for (int f = 0; f < 5; ++f) REQUIRE_FALSE(system.step(1.0 / 60));
        auto time = gpu->passTimes().find(pass);
        return time == gpu->passTimes().end() ? size_t{0} : time->second.launches;
    };
    CHECK(passes("fountain", "clear") == 0);
    CHECK(passes("fire", "clear") == 5 * 6);
    CHECK(passes("fountain", "init") == 5);
    CHECK(passes("fireworks", "init") <= 1);  // (a rocket every sixth step)
}

TEST_CASE("a pool of objects that only die keeps its rows on the GPU: what a step moves does not grow with them") {
    // The fountain at 2,000 and at 20,000 drops: the drops' rows — the free stack, the
    // generations, the masks — are on the GPU, and their rows, ids and creation times are
    // computed there; a step moves the same few hundred bytes between host and GPU (the
    // runs of the step's emissions, the counts of the kills) however many drops there are.
    auto perStep = [](float population) {
        auto gpu = gpuBackend();
        rt::System system(test::compileModule(readFile(test::sample("fountain"))), *gpu);
        REQUIRE_FALSE(system.setExtern("population", std::vector<float>{population}));
        for (int f = 0; f < 200; ++f) REQUIRE_FALSE(system.step(1.0 / 60));  // the pool full: drops die
        const rt::Pool& drops = system.pool(static_cast<size_t>(system.typeIndex("drop")));
        CHECK(drops.rowsInMemory());
        CHECK(drops.live() > population * 0.9);
        uint64_t before = gpu->transferredBytes(), waits = gpu->waits();
        for (int f = 0; f < 20; ++f) REQUIRE_FALSE(system.step(1.0 / 60));
        // One a step, however many drops: the fountain's emissions' totals (with no host
        // side its one row is on the GPU, and the GPU decides its emissions).
        CHECK(gpu->waits() - waits == 20);
        return static_cast<double>(gpu->transferredBytes() - before) / 20;
    };
    double small = perStep(2000), large = perStep(20000);
    MESSAGE("bytes between host and GPU a step: " << small << " with 2,000 drops, " << large << " with 20,000");
    CHECK(large <= 1.1 * small + 8);
    CHECK(large < 1024);
}

TEST_CASE("children and the parents they read keep their rows on the GPU: frozen parents freed there, nothing grows") {
    // The comet's tail reads the comet — its position, whether it is alive, its age — live
    // and after its death (frozen); comets die at random ages beside their tails, burst on
    // death, and a launcher makes more. Both
    // types keep their rows in the memory: against the interpreter object for object, row
    // for row; the frozen comets freed on the GPU once their last tail is.
    const char* comets = R"(
        object comet {
            pos = vec3(cos(age * (1 + rand())) * 5, 3 + sin(age * 2), sin(age) * 5);
            sprite(pos, white, 0.5);
            emit tail(nrand3() * 0.5) at 120 per second;
            emit tail(vec3(0, 1, 0)) count 3;
            on death { emit tail(vec3(1, 0, 0)) count 5; }
            kill when age > 0.5 + rand() * 2;
            @capacity(300)
            object tail(offset: vec3) {
                pos = comet.pos + offset * (1 + age);
                sprite(pos, vec4(0.6, 0.8, comet.alive ? 1 : 0, clamp(1 - age / 2)), 0.15 + comet.age * 0.01);
                kill when age > 0.2 + rand() * 3 || (!comet.alive && age > 1);
            }
        }
        object launcher { emit comet at 6 per second; kill when age > 4; }
        spawn launcher;
        spawn comet;)";
    test::Pair p(comets);
    size_t comet = static_cast<size_t>(p.gl->typeIndex("comet")), tail = static_cast<size_t>(p.gl->typeIndex("comet.tail"));
    CHECK(p.gl->pool(comet).rowsInMemory());
    CHECK(p.gl->pool(tail).rowsInMemory());
    uint64_t frozen = 0;
    for (int f = 0; f < 360; ++f) {
        p.steps(1, 1.0 / 60);
        p.compare();
        REQUIRE(test::poolRows(*p.cpu) == test::poolRows(*p.gl));
        frozen += p.stats("comet").frozen;
    }
    CHECK(frozen > 100);  // comets waited, frozen, for their tails
    CHECK(p.stats("comet").created == 25);
    CHECK(p.stats("comet.tail").dropped > 0);  // (at its capacity)
    CHECK(p.stats("comet").live + p.stats("comet").frozen == 0);
    // Parents that emit only in a burst at creation, and die: their update emits nothing,
    // yet its kill flags must stay on the GPU for the exports of its survivors — a killed
    // comet keeps the position of its last update before, for its tail.
    test::Pair bursts(R"(
        object comet {
            pos = vec3(age * 3, sin(age * 5), 0);
            emit tail count 3;
            kill when age > 0.3 + rand();
            object tail { point(comet.pos + vec3(0, age, 0), white, 1); kill when age > 2; }
        }
        object launcher { emit comet at 10 per second; kill when age > 2; }
        spawn launcher;)");
    CHECK(bursts.gl->pool(static_cast<size_t>(bursts.gl->typeIndex("comet"))).rowsInMemory());
    for (int f = 0; f < 150; ++f) {
        bursts.steps(1, 1.0 / 60);
        bursts.compare();
    }
    CHECK(bursts.stats("comet").frozen > 0);
    // follow_parent at 30 and at 300 comets: the same bytes a step.
    auto perStep = [](int comets) {
        auto gpu = gpuBackend();
        std::string text = readFile(test::sample("follow_parent"));
        for (int k = 1; k < comets; ++k) text += "\nspawn comet;";
        rt::System system(test::compileModule(text), *gpu);
        for (int f = 0; f < 30; ++f) REQUIRE_FALSE(system.step(1.0 / 60));
        uint64_t before = gpu->transferredBytes();
        for (int f = 0; f < 20; ++f) REQUIRE_FALSE(system.step(1.0 / 60));
        return static_cast<double>(gpu->transferredBytes() - before) / 20;
    };
    double small = perStep(30), large = perStep(300);
    MESSAGE("follow_parent, bytes between host and GPU a step: " << small << " with 30 comets, " << large << " with 300");
    CHECK(large <= 1.1 * small + 8);
    CHECK(large < 1024);
}

TEST_CASE("parents that another type folds over keep their rows on the GPU beside their children") {
    // tests/programs/step_parents_folded_over.psys: moths fold over the comets alive at
    // each step's start (a frozen comet, waiting for its tails, is not updatable: not
    // among them), as on the interpreter, object for object and row for row.
    test::Pair p(readFile(test::programsDir() + "/step_parents_folded_over.psys"));
    CHECK(p.gl->pool(static_cast<size_t>(p.gl->typeIndex("comet"))).rowsInMemory());
    CHECK(p.gl->pool(static_cast<size_t>(p.gl->typeIndex("comet.tail"))).rowsInMemory());
    uint64_t frozen = 0;
    for (int f = 0; f < 300; ++f) {
        p.steps(1, 1.0 / 60);
        p.compare();
        frozen += p.stats("comet").frozen;
    }
    CHECK(frozen > 20);
    CHECK(p.stats("comet").created == 12);
}

TEST_CASE("types that only die and that folds read keep their rows on the GPU: late kills, the survivors' exports") {
    // tests/programs/step_folded_types_that_die.psys: gnats fold over each other and die,
    // a swallow folds over the gnats alive at each step's start, mayflies die in their
    // first update (a trigger's too) and are folded over, and so are hornets, emitters of
    // gnats that die:
    // the interpreter's objects and rows, and no wait a step for their kills (they come a
    // frame late).
    test::Pair p(readFile(test::programsDir() + "/step_folded_types_that_die.psys"));
    for (const char* type : {"gnat", "mayfly", "hornet", "swallow", "swarm"})
        CHECK(p.gl->pool(static_cast<size_t>(p.gl->typeIndex(type))).rowsInMemory());
    uint64_t waits = 0;
    for (int f = 0; f < 240; ++f) {
        if (f == 20 || f == 21) p.fire("swat");  // (mayflies that die at once, a step late)
        uint64_t before = p.gpu->waits();
        p.steps(1, 1.0 / 60);
        if (f >= 10) waits = std::max(waits, p.gpu->waits() - before);
        p.compare();
    }
    CHECK(p.stats("gnat").killed > 200);
    CHECK(p.stats("gnat").dropped > 0);
    CHECK(p.stats("mayfly").killed > 400);
    CHECK(p.stats("hornet").killed > 3);
    CHECK(waits <= 3);  // (the totals of the swarm's, the hornets' and the new hornets' emissions)
}

TEST_CASE("objects a trigger creates that die in their first update are not drawn before the next step") {
    // Their kill lists are freed at the next step's end; until then the GPU has cleared
    // them in the alive mask the draws read, as the interpreter has frozen them.
    test::Pair p("object s(k: float) { point(vec3(k, 0, 0), white, 1); kill when k < 0.5; }\n"
                 "trigger boom { emit s(rand()) count 5000; }");
    p.steps(1, 1.0 / 60);
    p.fire("boom");
    size_t drawn = p.gl->points(0).size();
    CHECK(drawn == p.cpu->points(0).size());
    CHECK(drawn > 2000);
    CHECK(drawn < 3000);
    CHECK(p.gl->pool(0).rowsInMemory());
    p.steps(2, 1.0 / 60);  // freed once, at the end of the first (they are not updated, nor killed, again)
    p.compare();
    CHECK(p.gl->stats().types[0].killed == p.cpu->stats().types[0].killed);
}
