// Hot reload: a new System takes over an old one's objects (System::carryOver).
//
// Objects are carried over by type name, keeping their rows, generations and free lists,
// so an unchanged source continues bit for bit: the same rows are updated in the same
// order, new objects get the rows they would have got. A state slot, a kept parameter or
// an export is carried when the new type has one of the same name and type; a slot the
// new type adds starts as it would have at the object's creation (its init value,
// evaluated at the creation time with the carried parameters; parameters the old type did
// not keep read 0); what the new type no longer has is dropped. The report names the
// slots added and dropped, but for those split-kernels carries (ir/carried.h), which an
// edit renumbers and every update writes before they are read. Parents are kept when the
// new child type's parent type is the old one's; readers are counted again, and a frozen
// object nobody reads any more is freed. Time, the step count, ids and externs (by name
// and type) continue. The start does not run again, but for a `spawn` of a type the old
// start did not spawn: the edit added it, and it runs at the next step.
#include <algorithm>
#include <map>
#include <set>

#include "ir/carried.h"
#include "rt/rng.h"
#include "rt/system_create.h"
#include "rt/system_draw.h"
#include "rt/system_state.h"

namespace psys::rt {

namespace {

// One column from one memory to another, through the host.
void copyColumn(const Memory& from, Buffer a, Memory& to, Buffer b, size_t rows, size_t elementBytes) {
    if (rows == 0) return;
    std::vector<std::byte> bytes(rows * elementBytes);
    from.read(a, 0, rows, bytes.data());
    to.write(b, 0, rows, bytes.data());
}

// The value columns of `to` matched by name and type in `from`: (new index, old index).
template <typename Items>
std::vector<std::pair<size_t, int>> matchByName(const Items& to, const Items& from) {
    std::vector<std::pair<size_t, int>> out;
    for (size_t i = 0; i < to.size(); ++i) {
        int found = -1;
        for (size_t j = 0; j < from.size(); ++j)
            if (from[j].name == to[i].name && from[j].type == to[i].type) found = static_cast<int>(j);
        out.push_back({i, found});
    }
    return out;
}

void copyValues(const Memory& from, const ValueColumns& a, size_t i, Memory& to, const ValueColumns& b, size_t j,
                size_t rows) {
    for (int c = 0; c < a.type(i).width; ++c)
        copyColumn(from, a.column(i, static_cast<size_t>(c)), to, b.column(j, static_cast<size_t>(c)), rows, 4);
}

// One type's rows, columns and accumulators, from `old`'s type `ot` to `s`'s type `t`.
void carryType(const detail::State& old, size_t ot, detail::State& s, size_t t, ReloadReport& report) {
    const ir::Object& o = s.module.objects[t];
    const Pool& from = old.pools[ot];
    const ir::Object& oo = from.object();
    Pool& to = s.pools[t];
    size_t rows = from.rows();
    std::vector<Status> status(rows);
    for (uint32_t r = 0; r < rows; ++r) status[r] = from.status(r);
    to.restore(status, from.generations(), from.freeRows());
    std::copy(from.diedAt.begin(), from.diedAt.begin() + static_cast<std::ptrdiff_t>(rows), to.diedAt.begin());
    report.carried += from.live() + from.frozen();
    copyColumn(old.memory, from.created, s.memory, to.created, rows, 8);
    copyColumn(old.memory, from.ids, s.memory, to.ids, rows, 4);
    to.restoreMask({from.mask(), from.mask() + rows});
    to.fresh = from.freshRows();
    for (auto [i, j] : matchByName(o.state, oo.state)) {
        if (j >= 0) copyValues(old.memory, from.state, static_cast<size_t>(j), s.memory, to.state, i, rows);
        else if (!ir::isCarried(o.state[i])) report.newSlots.push_back(o.name + "." + o.state[i].name);
    }
    for (auto [j, i] : matchByName(oo.state, o.state))
        if (i < 0 && !ir::isCarried(oo.state[j])) report.lostSlots.push_back(o.name + "." + oo.state[j].name);
    for (size_t p = 0; p < o.params.size(); ++p) {
        if (to.paramColumn[p] < 0) continue;
        for (size_t q = 0; q < oo.params.size(); ++q)
            if (oo.params[q].name == o.params[p].name && oo.params[q].type == o.params[p].type && from.paramColumn[q] >= 0)
                copyValues(old.memory, from.params, static_cast<size_t>(from.paramColumn[q]), s.memory, to.params,
                           static_cast<size_t>(to.paramColumn[p]), rows);
    }
    for (auto [i, j] : matchByName(o.exports, oo.exports))
        if (j >= 0) copyValues(old.memory, from.exports, static_cast<size_t>(j), s.memory, to.exports, i, rows);
    for (size_t site = 0; site < o.emits.size() && site < oo.emits.size(); ++site)
        if (o.emits[site].target == oo.emits[site].target && o.emits[site].when == oo.emits[site].when)
            copyColumn(old.memory, from.emitted[site], s.memory, to.emitted[site], rows, 8);
    s.typeStats[t] = old.typeStats[ot];
}

// Parents where the parent type is the one it was; readers counted again; frozen objects
// nobody reads any more freed.
void reconnect(const detail::State& old, detail::State& s, const std::vector<int>& oldTypeOf) {
    auto name = [](const detail::State& state, int type) {
        return type < 0 ? std::string() : state.module.objects[static_cast<size_t>(type)].name;
    };
    for (size_t t = 0; t < s.pools.size(); ++t) {
        Pool& to = s.pools[t];
        int ot = oldTypeOf[t];
        int parentType = s.types[t].parentType;
        bool sameParent = ot >= 0 && parentType >= 0 &&
                          name(old, old.types[static_cast<size_t>(ot)].parentType) == name(s, parentType);
        for (uint32_t r = 0; r < to.rows(); ++r) {
            to.readers[r] = 0;
            to.parent[r] = sameParent && to.status(r) != Status::Free ? old.pools[static_cast<size_t>(ot)].parent[r] : Handle{};
        }
    }
    for (size_t t = 0; t < s.pools.size(); ++t) {
        int parentType = s.types[t].parentType;
        if (parentType < 0) continue;
        Pool& parents = s.pools[static_cast<size_t>(parentType)];
        const Pool& to = s.pools[t];
        for (uint32_t r = 0; r < to.rows(); ++r)
            if (to.status(r) != Status::Free && parents.matches(to.parent[r])) ++parents.readers[to.parent[r].row];
    }
    s.ledger.freeUnread();
    for (Pool& pool : s.pools) pool.uploadRows();  // (where the rows are in the memory)
}

}  // namespace

ReloadReport System::carryOver(const System& oldSystem) {
    detail::State& s = *state_;
    // What a device still owes the old system first, so that its pools are what they would
    // be on the host: its last step's rows freed, its kills counted.
    oldSystem.state_->ledger.settle(detail::Ledger::Wait::Yes);
    oldSystem.state_->ledger.releaseForReload();
    oldSystem.state_->parentsToHost();
    const detail::State& old = *oldSystem.state_;
    ReloadReport report;
    s.now = old.now;
    s.lastDt = old.lastDt;
    s.step = old.step;
    s.nextId = old.nextId;
    s.started = old.started;
    s.stats = old.stats;
    // Externs still there with their types keep the host's values (a new one: its default).
    std::vector<int> oldExtern(s.module.externs.size(), -1);
    for (size_t e = 0; e < s.module.externs.size(); ++e) {
        int j = old.module.externIndex(s.module.externs[e].name);
        if (j < 0 || old.module.externs[static_cast<size_t>(j)].type != s.module.externs[e].type) continue;
        oldExtern[e] = j;
        s.externs[e] = old.externs[static_cast<size_t>(j)];
    }
    if (s.module.instanced()) {  // the instances play on: slots, lives, transforms, their externs
        const bool carried = old.module.instanced();
        if (carried) {
            s.growInstances(old.instances.size());
            s.instances = old.instances;
            // (speeds and pause need the rows on the host: where the new program keeps
            // some in the backend's memory, every instance plays on at 1)
            if (checkSpeeds())
                for (detail::InstanceSlot& i : s.instances) i.speed = 1, i.paused = false;
        }
        const size_t oldValues = core::instanceRecordValues(old.module.externs.size());
        for (size_t slot = 0; slot < s.instances.size(); ++slot) {
            const Value* from = carried ? old.externs.data() + old.module.externs.size() + 1 + oldValues * slot : nullptr;
            Value* to = s.instanceRecord(slot);
            if (carried) std::copy(from, from + core::kInstanceOwnValues, to);
            for (size_t e = 0; e < oldExtern.size(); ++e)
                to[core::kInstanceOwnValues + e] = carried && oldExtern[e] >= 0
                                                       ? from[core::kInstanceOwnValues + static_cast<size_t>(oldExtern[e])]
                                                       : s.externs[e];
        }
    }
    ++s.externsVersion;
    std::vector<int> oldTypeOf(s.pools.size(), -1);
    std::vector<bool> kept(old.pools.size(), false);
    for (size_t t = 0; t < s.pools.size(); ++t) {
        oldTypeOf[t] = old.module.objectIndex(s.module.objects[t].name);
        if (oldTypeOf[t] < 0) continue;
        kept[static_cast<size_t>(oldTypeOf[t])] = true;
        carryType(old, static_cast<size_t>(oldTypeOf[t]), s, t, report);
    }
    for (size_t ot = 0; ot < old.pools.size(); ++ot) {
        if (kept[ot]) continue;
        report.dropped += old.pools[ot].live() + old.pools[ot].frozen();
        report.droppedTypes.push_back(old.module.objects[ot].name);
    }
    reconnect(old, s, oldTypeOf);
    initNewSlots(report);
    // A `spawn` of a type the old start did not spawn is one the edit added: it runs (at
    // the next start()); those the old start had are not repeated, and a removed one
    // removes nothing.
    if (old.started)
        for (size_t site = 0; site < s.module.start.emits.size(); ++site) {
            const std::string& target = s.module.start.emits[site].target;
            bool before = std::any_of(old.module.start.emits.begin(), old.module.start.emits.end(),
                                      [&](const ir::EmitSite& e) { return e.target == target; });
            if (before) continue;
            s.reloadSpawns.push_back(site);
            report.spawned.push_back(target);
        }
    drawing_->invalidate();
    return report;
}



// The state slots a reload added start as at creation: the init kernel over the carried
// objects, at their creation times, writing only the new slots.
void System::initNewSlots(const ReloadReport& report) {
    detail::State& s = *state_;
    for (size_t t = 0; t < s.pools.size(); ++t) {
        Pool& pool = s.pools[t];
        const ir::Object& o = pool.object();
        const ir::Kernel* init = s.types[t].init;
        std::set<size_t> fresh;
        for (size_t i = 0; i < o.state.size(); ++i)
            for (const std::string& n : report.newSlots)
                if (n == o.name + "." + o.state[i].name && o.state[i].init == ir::StateInit::Next) fresh.insert(i);
        size_t rows = pool.rows();
        if (fresh.empty() || !init || rows == 0) continue;
        ColumnLayout layout = columnLayout(o, *init);
        detail::Scratch scratch(s.memory), parents(s.memory);
        std::vector<Buffer> table;
        s.bindPool(t, layout, scratch, table);
        size_t next = 1000;  // scratch columns past bindPool's
        table[ColumnLayout::kNow] = pool.created;
        for (size_t p = 0; p < o.params.size(); ++p)
            if (pool.paramColumn[p] < 0)
                for (int c = 0; c < o.params[p].type.width; ++c)
                    table[static_cast<size_t>(layout.paramOffset[p] + c)] = scratch.at(next++, Elem::F32, rows);
        for (size_t i = 0; i < o.state.size(); ++i)
            if (!fresh.count(i))
                for (int c = 0; c < o.state[i].type.width; ++c)
                    table[static_cast<size_t>(layout.stateOffset[i] + c)] = scratch.at(next++, Elem::F32, rows);
        Buffer mask = scratch.at(next++, Elem::U8, rows);
        auto* carried = s.host<uint8_t>(mask);
        for (uint32_t r = 0; r < rows; ++r) carried[r] = pool.status(r) != Status::Free;
        RowsLaunch launch;
        launch.object = &o;
        launch.kernel = init;
        launch.layout = &layout;
        launch.columns = table;
        launch.mask = mask;
        launch.clock = {Clock::Source::PerRow, Clock::Source::Uniform, 0, 0, true};  // as at creation: dt 0
        launch.externs = s.externs.data();
        launch.seed = s.options.seed;
        launch.draw = kCreationDraw;
        launch.begin = 0;
        launch.end = rows;
        s.gatherParents(t, layout, table, carried, 0, rows, 0, s.host<double>(pool.created));
        s.backend.run(launch);
    }
}

}  // namespace psys::rt
