// The parts of the backend contract (rt/backend.h) every backend shares.
#include "rt/backend.h"

#include <cstring>

namespace psys::rt {

std::vector<ChildrenLaunch> eachEmitter(const Memory& memory, const ChildrenLaunch& launch, std::vector<Value>& parents) {
    if (launch.recordCount == 0) return {};
    static const std::vector<ColumnLayout::ParentColumn> none;
    const std::vector<ColumnLayout::ParentColumn>& reads = launch.layout ? launch.layout->parentColumns : none;
    std::vector<uint32_t> records(((launch.recordCount - 1) * launch.recordStride + 1) * kRunWords), rows;
    std::vector<double> nows;
    if (launch.nows.valid()) {
        nows.resize(launch.recordCount);
        memory.read(launch.nows, launch.nowsFirst, nows.size(), nows.data());
    }
    memory.read(launch.records, launch.record * kRunWords, records.size(), records.data());
    if (launch.rows.valid()) {
        rows.resize(launch.recordCount);
        memory.read(launch.rows, launch.rowsFirst, rows.size(), rows.data());
    }
    std::vector<ChildrenLaunch> each;
    size_t emitters = 0;
    for (size_t k = 0; k < launch.recordCount; ++k) emitters += records[k * launch.recordStride * kRunWords + 1] != 0;
    parents.assign(emitters * reads.size(), Value{});  // (sized once: the launches point into it)
    for (size_t k = 0; k < launch.recordCount; ++k) {
        const uint32_t* w = records.data() + k * launch.recordStride * kRunWords;
        if (w[1] == 0) continue;
        ChildrenLaunch& one = each.emplace_back(launch);
        one.records = one.rows = one.nows = {};
        one.record = one.recordCount = one.rowsFirst = one.placed = one.nowsFirst = 0;
        one.recordStride = 1;
        one.nowFromRecords = false;
        one.row = rows.empty() ? static_cast<uint32_t>(launch.rowsFirst + k) : rows[k];
        if (launch.nowFromRecords) std::memcpy(&one.clock.nowValue, w + 4, 8);
        if (!nows.empty()) one.clock.nowValue = nows[k];
        one.firstChild = w[2];
        one.count = w[1];
        one.argsFirst = launch.argsFirst + w[0];
        Value* its = parents.data() + (each.size() - 1) * reads.size();
        for (size_t i = 0; i < reads.size(); ++i)
            for (int c = 0; c < reads[i].width; ++c)
                memory.read(launch.columns[static_cast<size_t>(reads[i].offset + c)], one.row, 1,
                            &its[i].f[static_cast<size_t>(c)]);
        one.parents = its;
    }
    return each;
}

void Backend::runChildren(std::span<const ChildrenLaunch> launches) {
    for (const ChildrenLaunch& l : launches) {
        if (!l.records.valid()) {
            run(l);
            continue;
        }
        std::vector<Value> parents;
        runChildren(eachEmitter(memory(), l, parents));  // (none of them from records)
    }
}

}  // namespace psys::rt
