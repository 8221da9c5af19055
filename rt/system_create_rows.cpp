// Creating the objects of a type whose pool keeps its rows in the memory
// (Pool::keepRowsInMemory): the same batch as Creation::createBatch — rows by the
// allocation rule, ids and creation times from the runs, init, the first update to the
// step's end — with every per-object step an operation of the memory (rt::Memory::
// allocateRows, identify, scatter by a row list), so that on a device the host's work is
// the batch's, not its objects'. Such a type dies late or never, has no parent but one
// whose rows are there too (its objects' parent rows from the records of their parents'
// emissions: Memory::parentsFromRecords), and emits nothing or only what the memory
// decides (Creation::emitInMemory, here too: Memory::emitAtRate), in sub-steps or not
// (firstUpdateInMemory): after its first update (and its exports, of the survivors) an
// object only waits to be freed with the step's late kills (rt/ledger.h). What it folds
// over its neighbours is, for an object created in the step, a fold over nothing: filled
// in, not gathered (rt/neighbours.cpp).
#include "rt/system_create.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>

#include "rt/rng.h"
#include "rt/system_support.h"

namespace psys::rt::detail {

namespace {

// Whether a spawn kernel of the type reads an ancestor's age (a new emitter's sub-steps
// then gather it at each one's own clock: Creation::agesAtSubStep).
bool readsAncestorAge(const TypeInfo& info) {
    for (const ColumnLayout& layout : info.spawnLayout)
        for (const ColumnLayout::ParentColumn& p : layout.parentColumns)
            if (p.op == ir::Op::ParentAge) return true;
    return false;
}

}  // namespace

// The batch's tables (its init, update and exports; each burst site's, with parent
// columns of its own), a fold over nothing in their fold columns.
void Creation::bindInMemory(size_t type, Batch& b, size_t n) {
    const TypeInfo& info = s_.types[type];
    const ir::Object& o = s_.pools[type].object();
    const size_t first = b.first;
    if (info.init) bindBatch(type, b, b.initLayout, b.initParents, b.initTable, Table::Init);
    bindBatch(type, b, info.updateLayout, b.updateParents, b.updateTable, Table::Advanced);
    if (info.exports) bindBatch(type, b, info.exportsLayout, b.exportsParents, b.exportsTable, Table::Advanced);
    const bool bursts = info.bursts && info.init;  // (a burst's count is init's)
    b.burstTables.assign(o.emits.size(), {});
    for (size_t site = 0, parentsFirst = 0; bursts && site < o.emits.size(); ++site)
        if (o.emits[site].atCreation() && info.spawn[site]) {
            const ColumnLayout& layout = info.spawnLayout[site];
            bindBatch(type, b, layout, b.burstParents, b.burstTables[site], Table::Bursts, parentsFirst);
            parentsFirst += static_cast<size_t>(layout.total - layout.parents);
        }
    if (info.init) emptyFolds(type, b.initLayout, b.initTable, first, n);
    emptyFolds(type, info.updateLayout, b.updateTable, first, n);
    if (info.exports) emptyFolds(type, info.exportsLayout, b.exportsTable, first, n);
}

// The batch's ids and creation times (from its runs, and the records of the runs the
// memory decided); returns its mask (its first `kept` objects).
Buffer Creation::identifyInMemory(Batch& b, size_t n, size_t kept) {
    const size_t first = b.first;
    std::vector<Buffer>& table = b.updateTable;
    ObjectRuns runs;
    for (size_t u = 0; u < b.runs.size(); ++u) {
        const Run& run = b.runs[u];
        if (run.runs.valid()) continue;  // (identifyRecords, below)
        runs.first.push_back(static_cast<uint32_t>(b.runFirst[u]));
        runs.count.push_back(static_cast<uint32_t>(run.count));
        runs.id.push_back(run.id);
        runs.perEvent.push_back(static_cast<uint32_t>(std::min<uint64_t>(run.perEvent, UINT32_MAX)));
        runs.firstTime.push_back(run.firstTime);
        runs.spacing.push_back(run.spacing);
    }
    Memory& memory = s_.memory;
    Buffer mask = b.columns.at(kMask, Elem::U8, first + n);
    memory.identify(runs, n, kept, table[ColumnLayout::kCreated], table[ColumnLayout::kIds], mask, first);
    for (size_t u = 0; u < b.runs.size(); ++u)
        if (const Run& run = b.runs[u]; run.runs.valid())
            memory.identifyRecords(run.runs, run.record, run.records, run.count, table[ColumnLayout::kCreated],
                                   table[ColumnLayout::kIds], first + b.runFirst[u]);
    return mask;
}

// What a batch's bursts at creation read, in their tables: the state at creation (one
// copy: every burst table's), and each site's ancestor reads at each object's creation.
void Creation::burstTablesAtCreation(size_t type, Batch& b, size_t n) {
    const TypeInfo& info = s_.types[type];
    const ir::Object& o = s_.pools[type].object();
    const size_t first = b.first;
    const std::vector<Buffer>& table = b.updateTable;
    Memory& memory = s_.memory;
    for (const std::vector<Buffer>& t : b.burstTables) {
        if (t.empty()) continue;
        for (size_t s = 0; s < o.state.size(); ++s)
            for (int c = 0; c < o.state[s].type.width; ++c) {
                auto column = static_cast<size_t>(info.updateLayout.stateOffset[s] + c);
                memory.copy(table[column], first, t[column], first, n);
            }
        break;
    }
    for (size_t site = 0; site < o.emits.size(); ++site) {
        if (b.burstTables[site].empty()) continue;
        const ColumnLayout& layout = info.spawnLayout[site];
        if (s_.pools[type].parentRows.valid())
            s_.gatherThrough(type, layout, b.burstTables[site], b.columns.at(kParents, Elem::U32, first + n), first,
                             first, first + n, 0, table[ColumnLayout::kCreated]);
        emptyFolds(type, layout, b.burstTables[site], first, n);
    }
}

void Creation::createInMemory(size_t type, Batch& b, size_t n, double t1) {
    Pool& pool = s_.pools[type];
    const TypeInfo& info = s_.types[type];
    const ir::Object& o = pool.object();
    const size_t first = b.first;
    // (What it queues into its own type sees the pool's free rows, the batch's taken: as
    // the host's rule gives — the batch's later rows counted free less its later objects
    // still queued — unless the batch dropped some, when no row is free either way.)
    queued_[type] -= n;
    Buffer rows = pool.scratchRows(n);
    size_t kept = pool.allocate(n, rows, 0);  // the first `kept` objects: rows[0, kept)
    s_.typeStats[type].dropped += n - kept;
    if (kept == 0) {
        pool.recycle(rows);
        return;
    }
    s_.typeStats[type].created += kept;
    pool.createdRows(rows, kept);  // updatable from the next step on
    bindInMemory(type, b, n);
    const bool bursts = info.bursts && info.init;  // (a burst's count is init's)
    std::vector<Buffer>& table = b.updateTable;
    Memory& memory = s_.memory;
    Buffer mask = identifyInMemory(b, n, kept);
    std::vector<std::pair<Buffer, Buffer>> columns;
    identityColumns(type, table, columns);
    if (pool.parentRows.valid()) columns.push_back({parentsOf(type, b, n, kept), pool.parentRows});
    memory.scatter(columns, first, rows, 0, kept);

    for (size_t s : info.zeroedState)  // (what init sets is not)
        for (int c = 0; c < o.state[s].type.width; ++c)
            memory.clear(table[static_cast<size_t>(info.updateLayout.stateOffset[s] + c)], first, n);
    // Init at each object's creation time with dt 0; then one update to t1, dt each
    // object's age (Clock::Source::SinceCreated), its kills late.
    if (info.init) {
        b.initTable[ColumnLayout::kNow] = b.initTable[ColumnLayout::kCreated];
        launchInMemory(type, b, n, *info.init, b.initLayout, b.initTable,
                       {Clock::Source::PerRow, Clock::Source::Uniform, 0, 0, true}, nullptr);
    }
    const bool dies = info.kills || info.unstable;
    if (info.exports && dies) {  // what children read of an object its first update kills: its exports at creation
        Buffer zero = b.columns.at(kZero, Elem::F32, first + n);
        memory.clear(zero, first, n);
        b.exportsTable[ColumnLayout::kNow] = b.exportsTable[ColumnLayout::kCreated];
        b.exportsTable[ColumnLayout::kDt] = zero;
        launchInMemory(type, b, n, *info.exports, info.exportsLayout, b.exportsTable,
                       {Clock::Source::PerRow, Clock::Source::PerRow, 0, 0, true}, nullptr);
    }
    if (bursts) burstTablesAtCreation(type, b, n);
    if (info.updateEmits) {  // (their spawn launches read the pool's columns at its rows: the parents' at t1 —
                             // in sub-steps too, but for an ancestor's age: agesAtSubStep —
                             // and its own values as of the sub-step: firstUpdateInMemory)
        std::vector<size_t> sites;
        for (size_t site = 0; site < o.emits.size(); ++site)
            if (o.emits[site].inUpdate()) sites.push_back(site);
        s_.gatherSpawnParents(type, sites, t1);
    }
    LateKills late;
    columns.clear();
    const Clock toEnd = firstUpdateInMemory(type, b, n, kept, rows, t1, late, columns);
    const bool subSteps = toEnd.now == Clock::Source::PerRow;  // (their kills listed, their exports, each after its own)
    if (info.read && !subSteps) s_.ledger.listNow(late);  // its dead are dead to its children at once
    if (info.exports && !subSteps) exportSurvivors(type, b, n, mask, toEnd);
    valueColumns(type, b, columns);
    // Each object's bursts at creation, then its first update's emissions (in sub-steps:
    // firstUpdateInMemory's, each after its sub-step).
    if ((info.updateEmits || bursts) && toEnd.now == Clock::Source::Uniform)
        emitFromBatch(type, b, n, rows, t1, {bursts, info.updateEmits, true, mask, {}, {}}, columns);
    memory.scatter(columns, first, rows, 0, kept);
    if (!info.late) return;
    s_.ledger.defer(std::move(late));
}

// The batch's state and exports, with the pool's columns they go to.
void Creation::valueColumns(size_t type, const Batch& b, std::vector<std::pair<Buffer, Buffer>>& columns) const {
    const TypeInfo& info = s_.types[type];
    const Pool& pool = s_.pools[type];
    const ir::Object& o = pool.object();
    for (size_t s = 0; s < o.state.size(); ++s)
        for (int c = 0; c < o.state[s].type.width; ++c)
            columns.push_back({b.updateTable[static_cast<size_t>(info.updateLayout.stateOffset[s] + c)],
                               pool.state.column(s, static_cast<size_t>(c))});
    for (size_t e = 0; info.exports && e < o.exports.size(); ++e)
        for (int c = 0; c < o.exports[e].type.width; ++c)
            columns.push_back({b.exportsTable[static_cast<size_t>(info.exportsLayout.exportOffset[e] + c)],
                               pool.exports.column(e, static_cast<size_t>(c))});
}

// The exports of the rows of `mask` the update just run left alive (of a type that never
// dies: every one), at its clock; a row it killed keeps what it had.
void Creation::exportSurvivors(size_t type, Batch& b, size_t n, Buffer mask, const Clock& clock) {
    const TypeInfo& info = s_.types[type];
    const std::vector<Buffer>& table = b.updateTable;
    Buffer survivors = mask;
    if (info.kills) {
        survivors = b.columns.at(kExportMask, Elem::U8, b.first + n);
        s_.memory.survivors(mask, table[ColumnLayout::kKill], survivors, b.first, n);
    }
    b.exportsTable[ColumnLayout::kNow] = table[ColumnLayout::kNow];  // (sub-steps: each row's own)
    b.exportsTable[ColumnLayout::kDt] = table[ColumnLayout::kDt];
    launchInMemory(type, b, n, *info.exports, info.exportsLayout, b.exportsTable, clock, nullptr, survivors);
}

void Creation::emitFromBatch(size_t type, Batch& b, size_t n, Buffer rows, double t1, const BatchSites& which,
                             std::vector<std::pair<Buffer, Buffer>>& columns) {
    const TypeInfo& info = s_.types[type];
    const ir::Object& o = s_.pools[type].object();
    RateSites in;
    in.rows = n;
    in.first = b.first;
    in.mask = which.mask;
    if (info.kills) in.killed = b.updateTable[ColumnLayout::kKill];
    in.created = b.updateTable[ColumnLayout::kCreated];
    in.now = which.now;
    in.length = which.length;
    in.fresh = which.fresh;
    std::vector<size_t> sites;
    for (size_t site = 0; which.atCreation && site < o.emits.size(); ++site)
        if (o.emits[site].atCreation()) {
            in.sites.emplace_back().kind = RateSites::Site::Kind::AtCreation;
            sites.push_back(site);
        }
    for (size_t site = 0; which.inUpdate && site < o.emits.size(); ++site) {
        if (!o.emits[site].inUpdate()) continue;
        RateSites::Site& out = in.sites.emplace_back();
        out.kind = o.emits[site].rate() ? RateSites::Site::Kind::Rate : RateSites::Site::Kind::Burst;
        sites.push_back(site);
        if (!o.emits[site].rate()) continue;
        out.accumulated = emissions_.at(site, Elem::F64, b.first + n);
        if (which.fresh) columns.push_back({out.accumulated, s_.pools[type].emitted[site]});
    }
    emitInMemory(type, b.updateTable, nullptr, std::move(in), sites, &b, rows, t1);
}

// A hitch past kMaxSubSteps in a batch's first update: the objects whose own sub-steps
// are capped, counted (a read of their creation times).
void Creation::countCappedSubSteps(size_t type, Batch& b, size_t n, double t1) {
    std::vector<double> created(n);
    std::vector<uint8_t> kept(n);
    s_.memory.read(b.updateTable[ColumnLayout::kCreated], b.first, n, created.data());
    s_.memory.read(b.columns.at(kMask, Elem::U8, b.first + n), b.first, n, kept.data());
    uint64_t count = 0;
    for (size_t r = 0; r < n; ++r)
        if (kept[r]) subStepCount(t1 - created[r], s_.types[type].stepLimit, count);
    s_.typeStats[type].cappedSubSteps += count;
}

// A sub-step of a new emitter batch (its ends `nows`, by batch row): for each site whose
// spawn arguments read an ancestor's age, the site's spawn table with those ages as of
// each object's own sub-step end — gathered through the batch's parents
// (State::gatherThrough), put at the objects' pool rows (`rows`, where a launch from
// records reads its emitters) in columns of the batch's own — as the host clocks each
// object's emissions (Creation::killOrEmit); the sub-step's spawn launches run before the
// next (firstUpdateInMemory). What else the arguments read of an ancestor is the same at
// every sub-step, gathered once (State::gatherSpawnParents).
void Creation::agesAtSubStep(size_t type, Batch& b, size_t n, Buffer rows, Buffer nows) {
    const TypeInfo& info = s_.types[type];
    const size_t sites = info.spawnLayout.size(), end = b.first + n;
    std::vector<std::vector<Buffer>>& tables = b.agedTables;
    tables.assign(sites, {});
    auto onlyAges = [](const ColumnLayout& layout) {
        ColumnLayout ages = layout;
        std::erase_if(ages.parentColumns, [](const ColumnLayout::ParentColumn& p) { return p.op != ir::Op::ParentAge; });
        return ages;
    };
    size_t used = 0;  // (two columns an age a site: by batch row, by pool row)
    for (size_t site = 0; site < sites; ++site) {
        const ColumnLayout& layout = info.spawnLayout[site];
        const ColumnLayout ages = onlyAges(layout);
        if (ages.parentColumns.empty() || !s_.pools[type].object().emits[site].inUpdate()) continue;
        std::vector<Buffer> gathered(static_cast<size_t>(layout.total));
        tables[site] = s_.work[type].spawnTables[site];
        for (const ColumnLayout::ParentColumn& p : ages.parentColumns) {
            auto at = static_cast<size_t>(p.offset);
            gathered[at] = b.subStepAges.at(used++, Elem::F32, end);
            tables[site][at] = b.subStepAges.at(used++, Elem::F32, s_.pools[type].rows());
        }
        s_.gatherThrough(type, ages, gathered, b.columns.at(kParents, Elem::U32, end), b.first, b.first, end, 0, nows);
        std::vector<std::pair<Buffer, Buffer>> moved;
        for (const ColumnLayout::ParentColumn& p : ages.parentColumns)
            moved.push_back({gathered[static_cast<size_t>(p.offset)], tables[site][static_cast<size_t>(p.offset)]});
        s_.memory.scatter(moved, b.first, rows, 0, n);
    }
    b.inUpdateAged = true;
}

// The batch's first update to t1, its kills late (the last sub-step's into `late`); in
// sub-steps no longer than @step where an object's span may take more than one, each
// object through its own (Memory::subStepClocks), the k-th of each at once, what one
// kills taken out of the masks before the next (Ledger::takeOut) and freed at the step's
// end. Returns the clock its exports are computed at: each row's last.
Clock Creation::firstUpdateInMemory(size_t type, Batch& b, size_t n, size_t kept, Buffer rows, double t1,
                                    LateKills& late, std::vector<std::pair<Buffer, Buffer>>& columns) {
    const TypeInfo& info = s_.types[type];
    Pool& pool = s_.pools[type];
    std::vector<Buffer>& table = b.updateTable;
    auto lateKills = [&]() {
        LateKills l;
        l.type = type;
        l.t1 = t1;
        l.first = b.first;
        if (info.late) {
            l.map = rows;  // (released through it at a step's end: Ledger::releaseInMemory)
            pool.holdRows(rows);
        }
        return l;
    };
    late = lateKills();
    // The host does not know the creation times, but no object of a batch was created
    // before the step began (s_.now until its end) by more than the rounding of its time
    // (an event's time is a sum from the start of its emitter's update, a few units in the
    // last place off): the most sub-steps any of them takes.
    const double ulp = std::nextafter(std::fabs(t1), INFINITY) - std::fabs(t1);
    uint64_t capped = 0;
    const uint32_t most = subStepCount(t1 - s_.now + 16 * ulp, info.stepLimit, capped);
    if (most == 1) {
        const Clock toEnd{Clock::Source::Uniform, Clock::Source::SinceCreated, t1, 0, false};
        launchInMemory(type, b, n, *info.update, info.updateLayout, table, toEnd, info.late ? &late : nullptr);
        return toEnd;
    }
    Memory& memory = s_.memory;
    const size_t end = b.first + n;
    Buffer mask = b.columns.at(kMask, Elem::U8, end), step = b.columns.at(kStepMask, Elem::U8, end);
    if (capped) countCappedSubSteps(type, b, n, t1);
    const Clock perRow{Clock::Source::PerRow, Clock::Source::PerRow, 0, 0, false};
    // An emitter's: each sub-step's emissions after its update, over the sub-step's own
    // clock, before what it killed is taken out (its bursts on death are from them), and
    // their spawn launches before the next sub-step, reading its values as of this one; its
    // bursts at creation with the first's, each object's just before its own emissions,
    // as the host queues them (Creation::firstUpdate).
    const bool emits = info.updateEmits, bursts = info.bursts && info.init;
    // (A type children read: each sub-step's deaths at each object's own clock, now − length.)
    Buffer length = emits || info.read ? b.columns.at(kLength, Elem::F64, end) : Buffer{};
    Buffer taken;  // (the earlier sub-steps' kills, gathered: Ledger::takeOut)
    const bool agedArguments = emits && readsAncestorAge(info);
    for (uint32_t k = 1; k <= most; ++k) {
        memory.subStepClocks(table[ColumnLayout::kCreated], mask, step, table[ColumnLayout::kNow],
                             table[ColumnLayout::kDt], length, b.first, n, k, most, t1, info.stepLimit);
        // (The batch's column keeps each row's last sub-step end, its exports' clock.)
        const Buffer nows = emits ? table[ColumnLayout::kNow] : Buffer{};
        if (agedArguments) agesAtSubStep(type, b, n, rows, nows);
        std::optional<LateKills> each;
        if (info.late && k < most) each = lateKills();
        LateKills* kills = !info.late ? nullptr : k < most ? &*each : &late;
        launchInMemory(type, b, n, *info.update, info.updateLayout, table, perRow, kills, step);
        // (Where children read it: its dead dead to them at once, each at its own clock; a
        // row killed keeps its last sub-step's exports.)
        if (info.read && kills) s_.ledger.listNow(*kills, table[ColumnLayout::kNow], length);
        if (info.exports) exportSurvivors(type, b, n, step, perRow);
        if (emits || (bursts && k == 1))  // (in the first sub-step every object kept takes: step is mask)
            emitFromBatch(type, b, n, rows, t1,
                          {bursts && k == 1, emits, k == 1, step, nows, emits ? length : Buffer{}},
                          columns);
        b.inUpdateAged = false;
        if (emits && k < most && spawnsUsed_ != 0) {  // what it emitted reads its values as of this sub-step:
                                                       // before the next moves it on
            std::vector<std::pair<Buffer, Buffer>> values;
            valueColumns(type, b, values);
            memory.scatter(values, b.first, rows, 0, kept);
            runSpawns();
        }
        if (!each) continue;
        if (!taken.valid()) {
            taken = pool.scratchRows(n + 1);
            s_.ledger.deferGathered(type, taken);
        }
        s_.ledger.takeOut(*each, taken, step);
        s_.ledger.defer(std::move(*each));
    }
    return perRow;
}

// A child type's batch: each object's parent row, from the records of its parents'
// emissions, and each kept object a reader more of its parent (objects r < kept).
Buffer Creation::parentsOf(size_t type, Batch& b, size_t n, size_t kept) {
    Memory& memory = s_.memory;
    Buffer parents = b.columns.at(kParents, Elem::U32, b.first + n);
    Buffer readers = s_.pools[static_cast<size_t>(s_.types[type].parentType)].memoryRows().readers;
    for (size_t u = 0; u < b.runs.size(); ++u) {
        const Run& run = b.runs[u];
        size_t at = b.runFirst[u], its = kept > at ? std::min(kept - at, run.count) : 0;
        if (run.runs.valid()) {
            memory.parentsFromRecords(run.runs, run.record, run.records, run.stride, run.emitters, run.emittersFirst, run.count, its,
                                      parents, b.first + at, readers);
            continue;
        }
        // (A run the host queued: one parent, or none.)
        memory.fill(parents, b.first + at, run.count, run.parent.valid() ? run.parent.row : kSkipRow);
        if (!run.parent.valid() || its == 0) continue;
        uint32_t count = 0;
        memory.read(readers, run.parent.row, 1, &count);
        count += static_cast<uint32_t>(its);
        memory.write(readers, run.parent.row, 1, &count);
    }
    return parents;
}

void Creation::emptyFolds(size_t type, const ColumnLayout& layout, const std::vector<Buffer>& table, size_t first,
                          size_t n) {
    for (const auto& p : layout.parentColumns)
        if (p.op == ir::Op::Fold) s_.emptyFold(type, p, table, first, n);
}

// A launch over the batch's objects (those kept: its mask, or `mask`), in chunks; `late`: its kills
// listed, each chunk into a kill list of its own, and cleared in the pool's alive mask
// where the backend clearsKilled (through the batch's rows, late->map): until they are
// freed, at the end of the step, nothing draws them and the next step does not update
// them (a trigger's batch).
void Creation::launchInMemory(size_t type, Batch& b, size_t n, const ir::Kernel& kernel, const ColumnLayout& layout,
                              std::vector<Buffer>& table, const Clock& clock, LateKills* late, Buffer mask) {
    const size_t first = b.first, end = first + n;
    RowsLaunch launch;
    launch.object = &s_.pools[type].object();
    launch.kernel = &kernel;
    launch.layout = &layout;
    launch.columns = table;
    launch.mask = mask.valid() ? mask : b.columns.at(kMask, Elem::U8, end);
    launch.clock = clock;
    launch.externs = s_.externs.data();
    launch.uniformKernel = s_.uniformKernel(type, kernel);
    launch.seed = s_.options.seed;
    launch.draw = clock.first ? kCreationDraw : static_cast<uint32_t>(s_.step);
    const TypeInfo& info = s_.types[type];
    launch.emissionsStay = info.updateEmits || (info.kills && info.exports);  // (as runUpdate's)
    if (s_.pools[type].parentRows.valid())  // its parents' values as they are now, at the launch's clock
        s_.gatherThrough(type, layout, table, b.columns.at(kParents, Elem::U32, end), first, first, end, clock.nowValue,
                         clock.now == Clock::Source::PerRow ? table[ColumnLayout::kNow] : Buffer{});
    if (late) {
        size_t per = s_.backend.chunkRows(), chunks = s_.chunkCount(n);
        late->parts.resize(chunks);
        for (size_t c = 0; c < chunks; ++c)
            late->parts[c].killList = s_.pools[type].scratchRows(std::min(per, n - c * per) + 1);
    }
    std::atomic<uint64_t> unstable = 0;
    s_.forChunks(first, end, [&](size_t c, size_t begin, size_t stop) {
        RowsLaunch part = launch;
        part.begin = begin;
        part.end = stop;
        part.late = late != nullptr;
        if (late) {
            part.killList = late->parts[c].killList;
            part.aliveMask = s_.pools[type].alive.column;
            part.aliveRowsBuffer = late->map;
            part.aliveRowsFirst = first;
        }
        RowsResult result = s_.backend.run(part);
        if (result.unstable) unstable += result.unstable;
        if (late) s_.ledger.record(late->parts[c], result, table[ColumnLayout::kKill], begin, stop);
    });
    s_.typeStats[type].unstable += unstable;
}

}  // namespace psys::rt::detail
