// The parts of the backend contract every backend shares (rt/backend.h, rt/memory.h):
// the host memory's gather, and a children launch from records run as one launch an
// emitter.
#include <doctest/doctest.h>

#include <cstring>

#include <stdexcept>
#include <string>
#include <vector>

#include "rt/backend.h"
#include "rt/memory.h"

using namespace psys;

TEST_CASE("a gather reads the rows it names, 0 for a skipped row — past the end is an error") {
    rt::HostMemory memory;
    rt::Buffer from = memory.create(rt::Elem::F32, 4), to = memory.create(rt::Elem::F32, 5);
    std::vector<float> values = {10, 11, 12, 13}, filled(5, -1);
    memory.write(from, 0, 4, values.data());
    memory.write(to, 0, 5, filled.data());
    std::vector<uint32_t> rows = {3, rt::kSkipRow, 1};
    memory.gather(from, to, 1, rows);
    const float* out = rt::viewData<float>(memory, to);
    CHECK(std::vector<float>(out, out + 5) == std::vector<float>{-1, 13, 0, 11, -1});
    std::vector<uint32_t> past = {4};
    CHECK_THROWS_AS(memory.gather(from, to, 0, past), std::out_of_range);
    CHECK_THROWS_AS(memory.gather(from, to, 3, rows), std::out_of_range);
}

namespace {

// Records the children launches the default runChildren runs.
struct ChildrenSeen : rt::Backend {
    rt::HostMemory host;
    std::vector<rt::ChildrenLaunch> seen;
    std::vector<rt::Value> parents;  // each launch's first parent read, where it has one
    std::string name() const override { return "children seen"; }
    rt::Memory& memory() override { return host; }
    rt::RowsResult run(const rt::RowsLaunch&) override { return {}; }
    void run(const rt::ChildrenLaunch& l) override {
        seen.push_back(l);
        if (l.parents) parents.push_back(l.parents[0]);
    }
};

}  // namespace

TEST_CASE("a launch from records runs as one launch an emitter with children: its row, place and first id") {
    ChildrenSeen backend;
    rt::Memory& memory = backend.memory();
    // Records 1 to 3 of a runs buffer (the first is another site's): place, count, id, …
    std::vector<uint32_t> words(4 * rt::kRunWords, 0);
    auto record = [&](size_t r, uint32_t place, uint32_t count, uint32_t id) {
        words[r * rt::kRunWords] = place;
        words[r * rt::kRunWords + 1] = count;
        words[r * rt::kRunWords + 2] = id;
    };
    record(0, 0, 50, 1);
    record(1, 0, 2, 7);
    record(2, 2, 0, 9);
    record(3, 2, 3, 9);
    const double created = 2.25;  // (record 3's first time)
    std::memcpy(&words[3 * rt::kRunWords + 4], &created, 8);
    rt::Buffer runs = memory.create(rt::Elem::U32, words.size()), rows = memory.create(rt::Elem::U32, 4);
    memory.write(runs, 0, words.size(), words.data());
    std::vector<uint32_t> rowList = {99, 5, 8, 11};
    memory.write(rows, 0, 4, rowList.data());
    rt::ChildrenLaunch launch;
    launch.count = 5;
    launch.argsFirst = 40;
    launch.records = runs;
    launch.record = 1;
    launch.recordCount = 3;
    launch.rows = rows;
    launch.rowsFirst = 1;
    // Its spawn kernel reads a parent's vec2 export: each emitter's from two columns at its
    // row (rt::detail::State::gatherSpawnParents), 10·row + component.
    rt::ColumnLayout layout;
    layout.parentColumns.push_back({ir::Op::ParentExport, 1, 0, 2, 0});
    std::vector<rt::Buffer> columns = {memory.create(rt::Elem::F32, 12), memory.create(rt::Elem::F32, 12)};
    for (size_t c = 0; c < 2; ++c)
        for (uint32_t row = 0; row < 12; ++row) {
            float value = static_cast<float>(10 * row + c);
            memory.write(columns[c], row, 1, &value);
        }
    launch.layout = &layout;
    launch.columns = columns;
    std::vector<rt::ChildrenLaunch> all = {launch};
    launch.records = {};  // an ordinary launch beside it runs as it is
    launch.row = 3;
    all.push_back(launch);
    backend.runChildren(all);
    REQUIRE(backend.seen.size() == 3);
    auto& s = backend.seen;
    CHECK((s[0].row == 5 && s[0].count == 2 && s[0].argsFirst == 40 && s[0].firstChild == 7));
    CHECK((s[1].row == 11 && s[1].count == 3 && s[1].argsFirst == 42 && s[1].firstChild == 9));
    CHECK_FALSE(s[0].records.valid());
    CHECK((s[2].row == 3 && s[2].count == 5));
    REQUIRE(backend.parents.size() == 2);  // (the ordinary launch has none: its parents are the host's)
    CHECK((backend.parents[0].f[0] == 50 && backend.parents[0].f[1] == 51));
    CHECK((backend.parents[1].f[0] == 110 && backend.parents[1].f[1] == 111));
    // Without a row list, record k is row rowsFirst + k.
    all[0].rows = {};
    std::vector<rt::Value> parents;
    std::vector<rt::ChildrenLaunch> each = rt::eachEmitter(memory, all[0], parents);
    REQUIRE(each.size() == 2);
    CHECK((each[0].row == 1 && each[1].row == 3));
    CHECK(each[0].clock.nowValue == all[0].clock.nowValue);
    // A group's site: every other record (rt::RecordLayout), each emitter's clock at its
    // record's first time (a burst at creation).
    all[0].recordCount = 2;
    all[0].recordStride = 2;
    all[0].nowFromRecords = true;
    each = rt::eachEmitter(memory, all[0], parents);
    REQUIRE(each.size() == 2);  // (records 1 and 3)
    CHECK((each[0].row == 1 && each[0].count == 2 && each[0].argsFirst == 40 && each[0].firstChild == 7));
    CHECK((each[1].row == 2 && each[1].count == 3 && each[1].argsFirst == 42 && each[1].firstChild == 9));
    CHECK(each[1].clock.nowValue == created);
    CHECK((each[1].parents == &parents[1] && parents[1].f[0] == 20));
}
