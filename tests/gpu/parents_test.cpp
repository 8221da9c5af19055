// A child's parents where both keep their rows on the GPU: the rows and values a child
// reads of its parents and of ancestors further up, from the records of their emissions,
// on the GPU against the same operations on the host (rt/memory.cpp; GLSL in
// gpu/gl_rows.cpp and gpu/gl_parents.cpp).
#include <doctest/doctest.h>

#include <cstring>
#include <random>
#include <vector>

#include "gpu_support.h"
#include "rt/clock.h"
#include "rt/memory.h"

using namespace psys;
using psys::test::gpuBackend;

TEST_CASE("a grandchild's grandparents' rows through its parents' rows, on the GPU as on the host") {
    // 5,000 grandchildren, each row a parent's (or none) of 700 parents, each of those a
    // grandparent's (or none): one level further up, none staying none.
    auto gpu = gpuBackend();
    rt::HostMemory hostMemory;
    constexpr size_t kChildren = 5000, kParents = 700;
    std::mt19937 random(17);
    std::vector<uint32_t> rows(kChildren), parents(kParents), expected(kChildren);
    for (uint32_t& p : parents) p = random() % 6 == 0 ? rt::kSkipRow : static_cast<uint32_t>(random() % 300);
    for (size_t i = 0; i < kChildren; ++i) {
        rows[i] = random() % 9 == 0 ? rt::kSkipRow : static_cast<uint32_t>(random() % kParents);
        expected[i] = rows[i] == rt::kSkipRow ? rt::kSkipRow : parents[rows[i]];
    }
    for (rt::Memory* m : {static_cast<rt::Memory*>(&hostMemory), &gpu->memory()}) {
        rt::Buffer r = m->create(rt::Elem::U32, kChildren + 10), p = m->create(rt::Elem::U32, kParents),
                   out = m->create(rt::Elem::U32, kChildren + 20);
        m->write(r, 10, kChildren, rows.data());
        m->write(p, 0, kParents, parents.data());
        m->ancestorRows(p, out, 20, r, 10, kChildren);
        std::vector<uint32_t> got(kChildren);
        m->read(out, 20, kChildren, got.data());
        CHECK(got == expected);
    }
}

TEST_CASE("a child's parents: from the records, their values, whether they are alive and their ages, on the GPU as on the host") {
    auto gpu = gpuBackend();
    rt::HostMemory hostMemory;
    // Records of 3 sites a row over 40 emitter rows (a batch's: through a map), each asking
    // for 0–4 objects in order.
    constexpr size_t kEmitters = 40, kStride = 3;
    std::mt19937 random(5);
    std::vector<uint32_t> runs, map(kEmitters);
    uint32_t objects = 0;
    for (size_t j = 0; j < kEmitters * kStride; ++j) {
        uint32_t count = random() % 5;
        std::vector<uint32_t> record(rt::kRunWords, 0);
        record[0] = objects;
        record[1] = count;
        objects += count;
        runs.insert(runs.end(), record.begin(), record.end());
    }
    for (uint32_t& m : map) m = 100 + random() % 50;
    std::vector<float> exported(200);
    for (float& v : exported) v = static_cast<float>(random() % 1000) / 7.0f;
    std::vector<uint8_t> alive(200), mask(objects), killed(objects);
    std::vector<double> createdAt(200), childClocks(objects);
    for (double& c : createdAt) c = 7.25 - static_cast<double>(random() % 100000) / 3e4;
    for (double& c : childClocks) c = 7.25 - static_cast<double>(random() % 1000) / 7e3;
    std::vector<uint32_t> dying{0}, dyingFirst{0};  // the dead parents (alive 0), in two kill lists
    for (uint32_t p = 0; p < 200; ++p) (p % 2 ? dying : dyingFirst).push_back(p);
    dying[0] = static_cast<uint32_t>(dying.size() - 1);
    dyingFirst[0] = static_cast<uint32_t>(dyingFirst.size() - 1);
    for (uint8_t& a : alive) a = random() % 2;
    for (uint8_t& m : mask) m = random() % 4 != 0;
    for (uint8_t& k : killed) k = random() % 3 == 0;
    struct Out {
        std::vector<uint32_t> parents, readers;
        std::vector<float> values, isAlive, ages, agesPerRow;
        std::vector<uint8_t> survivors;
    } out[2];
    int which = 0;
    for (rt::Memory* m : {static_cast<rt::Memory*>(&hostMemory), &gpu->memory()}) {
        rt::Buffer r = m->create(rt::Elem::U32, runs.size()), through = m->create(rt::Elem::U32, kEmitters);
        rt::Buffer parents = m->create(rt::Elem::U32, objects + 7), readers = m->create(rt::Elem::U32, 200);
        rt::Buffer from = m->create(rt::Elem::F32, 200), a = m->create(rt::Elem::U8, 200);
        rt::Buffer values = m->create(rt::Elem::F32, objects + 7), isAlive = m->create(rt::Elem::F32, objects + 7);
        rt::Buffer k = m->create(rt::Elem::U8, objects), ma = m->create(rt::Elem::U8, objects), s = m->create(rt::Elem::U8, objects);
        m->write(r, 0, runs.size(), runs.data());
        m->write(through, 0, kEmitters, map.data());
        m->write(from, 0, 200, exported.data());
        m->write(a, 0, 200, alive.data());
        m->write(k, 0, objects, killed.data());
        m->write(ma, 0, objects, mask.data());
        // (the group's records from record 0; objects kept: all but the last 9)
        m->parentsFromRecords(r, 0, kEmitters * kStride, kStride, through, 0, objects, objects - 9, parents, 7, readers);
        m->gatherThrough(from, values, 7, parents, 7, objects);
        m->gatherAlive(a, isAlive, 7, parents, 7, objects);
        // Ages: the parents' creation times, their deaths stamped from a kill list (half at a
        // uniform time, half from their creation), at a uniform clock and at per-row ones.
        rt::Buffer created = m->create(rt::Elem::F64, 200), frozenAt = m->create(rt::Elem::F64, 200),
                   clocks = m->create(rt::Elem::F64, objects + 7), list = m->create(rt::Elem::U32, 201);
        m->write(created, 0, 200, createdAt.data());
        m->write(clocks, 7, objects, childClocks.data());
        m->write(list, 0, dying.size(), dying.data());
        m->stampDeaths(list, 0, 0, {}, 0, frozenAt, 7.25, 1.0 / 60, {});
        m->write(list, 0, dyingFirst.size(), dyingFirst.data());
        m->stampDeaths(list, 0, 0, {}, 0, frozenAt, 7.25, 0, created);
        rt::Buffer ages = m->create(rt::Elem::F32, objects + 7), agesPerRow = m->create(rt::Elem::F32, objects + 7);
        m->gatherAge(created, frozenAt, a, ages, 7, parents, 7, objects, 7.25, {}, 0);
        m->gatherAge(created, frozenAt, a, agesPerRow, 7, parents, 7, objects, 0, clocks, 7);
        m->survivors(ma, k, s, 0, objects);
        Out& o = out[which++];
        o.parents.resize(objects);
        o.readers.resize(200);
        o.values.resize(objects);
        o.isAlive.resize(objects);
        o.survivors.resize(objects);
        m->read(parents, 7, objects, o.parents.data());
        m->read(readers, 0, 200, o.readers.data());
        m->read(values, 7, objects, o.values.data());
        m->read(isAlive, 7, objects, o.isAlive.data());
        m->read(s, 0, objects, o.survivors.data());
        o.ages.resize(objects);
        o.agesPerRow.resize(objects);
        m->read(ages, 7, objects, o.ages.data());
        m->read(agesPerRow, 7, objects, o.agesPerRow.data());
    }
    // The host's, against the records by hand: object r of emitter row j's records.
    uint32_t r = 0;
    std::vector<uint32_t> readers(200, 0);
    for (size_t j = 0; j < kEmitters * kStride; ++j)
        for (uint32_t k = 0; k < runs[j * rt::kRunWords + 1]; ++k, ++r) {
            REQUIRE(out[0].parents[r] == map[j / kStride]);
            if (r < objects - 9) ++readers[map[j / kStride]];
            CHECK(out[0].values[r] == exported[map[j / kStride]]);
            CHECK(out[0].isAlive[r] == (alive[map[j / kStride]] ? 1.0f : 0.0f));
            uint32_t p = map[j / kStride];
            double died = p % 2 ? 7.25 - 1.0 / 60 : 7.25 - (7.25 - createdAt[p]);
            CHECK(out[0].ages[r] == rt::ageAt(alive[p] ? 7.25 : died, createdAt[p]));
            CHECK(out[0].agesPerRow[r] == rt::ageAt(alive[p] ? childClocks[r] : died, createdAt[p]));
        }
    CHECK(out[0].readers == readers);
    CHECK(out[0].parents == out[1].parents);
    CHECK(out[0].readers == out[1].readers);
    CHECK(out[0].values == out[1].values);
    CHECK(out[0].isAlive == out[1].isAlive);
    CHECK(out[0].survivors == out[1].survivors);
    CHECK(out[0].ages == out[1].ages);
    CHECK(out[0].agesPerRow == out[1].agesPerRow);
    for (uint32_t i = 0; i < objects; ++i) CHECK(out[0].survivors[i] == (mask[i] && !killed[i]));
}
