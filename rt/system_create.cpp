// Creating objects: their creation in batches, from the queue (rt/system_queue.cpp) and
// its staging columns (rt/system_create.h).
#include "rt/system_create.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <optional>

#include "rt/rng.h"
#include "rt/system_draw.h"
#include "rt/system_support.h"

namespace psys::rt::detail {

using ir::KernelKind;
using ir::YieldKind;

namespace {

size_t components(const std::vector<ir::StateSlot>& slots) {
    size_t n = 0;
    for (const auto& s : slots) n += static_cast<size_t>(s.type.width);
    return n;
}

}  // namespace

Creation::Creation(State& state) : s_(state), emissions_(state.memory), runs_(state.memory) {
    queued_.assign(s_.pools.size(), 0);
    pending_.assign(s_.pools.size(), 0);
    staging_.resize(s_.pools.size());
    for (size_t t = 0; t < s_.pools.size(); ++t) {
        for (const ir::Param& p : s_.module.objects[t].params)
            for (int c = 0; c < p.type.width; ++c) staging_[t].args.push_back(s_.memory.create(Elem::F32, 0));
        batches_.emplace_back(s_.memory);
        const ir::Object& o = s_.module.objects[t];
        if (s_.types[t].init) batches_[t].initLayout = columnLayout(o, *s_.types[t].init);
    }
}

Creation::~Creation() {
    for (Staging& st : staging_)
        for (Buffer b : st.args) s_.memory.release(b);
}

// A table over the batch's scratch columns for `layout`: the staging columns as the
// parameters, the state at creation (bursts) or the state being advanced.
void Creation::bindBatch(size_t type, Batch& b, const ColumnLayout& layout, Scratch& parents,
                         std::vector<Buffer>& table, Table which, size_t parentsFirst) {
    const bool atCreation = which == Table::Bursts;
    const ir::Object& o = s_.module.objects[type];
    size_t rows = staging_[type].used;
    size_t stateCount = components(o.state), exportCount = 0;
    for (const auto& e : o.exports) exportCount += static_cast<size_t>(e.type.width);
    table.assign(static_cast<size_t>(layout.total), Buffer{});
    table[ColumnLayout::kCreated] = b.columns.at(kCreated, Elem::F64, rows);
    table[ColumnLayout::kIds] = b.columns.at(kIds, Elem::U32, rows);
    table[ColumnLayout::kKill] = b.columns.at(kKill, Elem::U8, rows);
    table[ColumnLayout::kNow] = b.columns.at(kNow, Elem::F64, rows);
    table[ColumnLayout::kDt] = b.columns.at(kDt, Elem::F32, rows);
    size_t component = 0;
    for (size_t s = 0; s < o.state.size(); ++s)
        for (int c = 0; c < o.state[s].type.width; ++c, ++component)
            table[static_cast<size_t>(layout.stateOffset[s] + c)] =
                b.columns.at(kFirstValue + (atCreation ? stateCount : 0) + component, Elem::F32, rows);
    component = 0;
    for (size_t p = 0; p < o.params.size(); ++p)
        for (int c = 0; c < o.params[p].type.width; ++c)
            table[static_cast<size_t>(layout.paramOffset[p] + c)] = staging_[type].args[component++];
    component = 0;
    for (size_t e = 0; e < o.exports.size(); ++e)
        for (int c = 0; c < o.exports[e].type.width; ++c, ++component)
            table[static_cast<size_t>(layout.exportOffset[e] + c)] =
                b.columns.at(kFirstValue + 2 * stateCount + component, Elem::F32, rows);
    size_t emitsAt = kFirstValue + 2 * stateCount + exportCount;
    if (which == Table::Init) emitsAt += 2 * o.emits.size() + static_cast<size_t>(layout.renderColumns);  // (after the render columns)
    for (size_t e = 0; e < 2 * o.emits.size(); ++e)
        table[static_cast<size_t>(layout.emits) + e] = b.columns.at(emitsAt + e, Elem::F32, rows);
    for (int c = 0; c < layout.renderColumns; ++c)  // what a render kernel writes
        if (layout.needs(layout.render + c))
            table[static_cast<size_t>(layout.render + c)] = b.columns.at(
                kFirstValue + 2 * stateCount + exportCount + 2 * o.emits.size() + static_cast<size_t>(c), Elem::F32, rows);
    for (size_t p = 0; p < layout.parentColumns.size(); ++p)
        for (int c = 0; c < layout.parentColumns[p].width; ++c) {
            size_t column = static_cast<size_t>(layout.parentColumns[p].offset + c);
            table[column] = parents.at(parentsFirst + column - static_cast<size_t>(layout.parents), Elem::F32, rows);
        }
}

// Creates the objects of runs queue_[from, to), all of one type: see rt/system_create.h
// (one run an object where objects are not created in batches). Rows are allocated
// in queue order (what does not fit is dropped and counted); init, exports at creation
// and the first update run over the whole batch; then object by object, in queue order,
// its bursts, its death or its emissions. While an object emits in its update (its first
// sub-step), the rows allocated for the objects after it count as free, as they would if
// each object were created alone; at a later sub-step they are all there.
void Creation::createBatch(size_t type, size_t from, size_t to, double t1) {
    runSpawns();  // the arguments of what the last batch queued (it reads its batch's columns)
    Pool& pool = s_.pools[type];
    const TypeInfo& info = s_.types[type];
    const ir::Object& o = pool.object();
    Batch& b = batches_[type];
    // Its runs, kept (creating it queues more runs) with each one's first object in the batch.
    b.runs.assign(queue_.begin() + static_cast<std::ptrdiff_t>(from), queue_.begin() + static_cast<std::ptrdiff_t>(to));
    b.runFirst.clear();
    size_t n = 0;
    for (const Run& run : b.runs) {
        b.runFirst.push_back(n);
        n += run.count;
    }
    b.first = b.runs.front().staging;
    if (pool.rowsInMemory()) {
        createInMemory(type, b, n, t1);
        return;
    }
    b.poolRows.resize(n);
    size_t allocated = pool.allocate(n, b.poolRows.data());  // the allocation rule (rt/allocation.h)
    s_.typeStats[type].dropped += n - allocated;
    if (allocated == 0) {
        queued_[type] -= n;
        return;
    }
    s_.typeStats[type].created += allocated;
    if (info.init) bindBatch(type, b, b.initLayout, b.initParents, b.initTable, Table::Init);
    bindBatch(type, b, info.updateLayout, b.updateParents, b.updateTable, Table::Advanced);
    if (info.exports) bindBatch(type, b, info.exportsLayout, b.exportsParents, b.exportsTable, Table::Advanced);
    b.burstTables.resize(o.emits.size());
    for (size_t site = 0; site < o.emits.size(); ++site)
        if (o.emits[site].atCreation() && info.spawn[site])
            bindBatch(type, b, info.spawnLayout[site], b.initParents, b.burstTables[site], Table::Bursts);
    identify(type, b, n);
    atCreation(type, b, n);
    firstUpdate(type, b, n, allocated, t1);
    const DrawnInStep& drawing = s_.work[type].inStep;
    if (drawing.on && drawing.updated) drawBatch(type, b, n, t1);
}

// Drawing as the step goes (rt/system_draw.h): objects created after their type's update
// are rendered here, in the batch, and their render columns scattered into the pool's.
void Creation::drawBatch(size_t type, Batch& b, size_t n, double t1) {
    const TypeInfo& info = s_.types[type];
    const ColumnLayout& layout = info.renderLayout;
    Pool& pool = s_.pools[type];
    TypeWork& work = s_.work[type];
    const size_t first = b.first, end = first + n;
    bindBatch(type, b, layout, b.renderParents, b.renderTable, Table::Advanced);
    Buffer mask = b.columns.at(kRenderMask, Elem::U8, end);
    auto* shown = s_.host<uint8_t>(mask);
    s_.forRows(0, n, [&](size_t begin, size_t end) {  // not those dropped, nor those that died in their first update
        for (size_t r = begin; r < end; ++r)
            shown[first + r] = b.poolRows[r] != kSkipRow && pool.status(b.poolRows[r]) == Status::Alive;
    });
    RowsLaunch launch = renderLaunch(s_, type, b.renderTable, mask, t1);
    std::atomic<uint64_t> drawn = 0, nonFinite = 0;
    s_.forChunks(first, end, [&](size_t, size_t begin, size_t stop) {
        DrawnCount count = renderRows(s_, type, launch, shown, begin, stop, b.poolRows.data(), first);
        drawn += count.drawn;
        nonFinite += count.nonFinite;
    });
    work.inStep.drawn += drawn;
    work.inStep.nonFinite += nonFinite;
    s_.bindPool(type, layout, work.render, work.renderTable);
    std::vector<std::pair<Buffer, Buffer>>& columns = b.scattered;
    columns.clear();
    for (int c = 0; c < layout.renderColumns; ++c)
        if (int column = layout.render + c; layout.needs(column))
            columns.push_back({b.renderTable[static_cast<size_t>(column)], work.renderTable[static_cast<size_t>(column)]});
    s_.scatter(columns, first, b.poolRows);
}

// The batch's objects in its columns and their pool rows: creation times, ids, parents
// (and their readers), kept parameters; the state init does not set, zeroed.
void Creation::identify(size_t type, Batch& b, size_t n) {
    Pool& pool = s_.pools[type];
    const TypeInfo& info = s_.types[type];
    const ir::Object& o = pool.object();
    const size_t first = b.first, end = first + n;
    const std::vector<Buffer>& table = b.updateTable;
    auto* mask = s_.host<uint8_t>(b.columns.at(kMask, Elem::U8, end));
    auto* created = s_.host<double>(table[ColumnLayout::kCreated]);
    auto* ids = s_.host<uint32_t>(table[ColumnLayout::kIds]);
    s_.forRows(0, n, [&](size_t begin, size_t end) {  // rows of their own: on every thread
        // The run of object `begin`, then each run's objects in order.
        size_t u = static_cast<size_t>(std::upper_bound(b.runFirst.begin(), b.runFirst.end(), begin) - b.runFirst.begin()) - 1;
        for (size_t r = begin; r < end; ++r) {
            while (r >= b.runFirst[u] + b.runs[u].count) ++u;
            const Run& run = b.runs[u];
            size_t k = r - b.runFirst[u];
            size_t i = first + r;
            uint32_t row = b.poolRows[r];
            mask[i] = row != kSkipRow;
            if (!mask[i]) continue;
            created[i] = run.time(k);
            ids[i] = run.id + static_cast<uint32_t>(k);
            pool.parent[row] = run.parent;
        }
    });
    if (info.parentType >= 0)  // several children may share a parent: its readers counted
        for (size_t u = 0; u < b.runs.size(); ++u) {
            const Run& run = b.runs[u];
            if (!run.parent.valid()) continue;
            size_t kept = 0;
            for (size_t r = b.runFirst[u]; r < b.runFirst[u] + run.count; ++r) kept += b.poolRows[r] != kSkipRow;
            s_.pools[static_cast<size_t>(info.parentType)].readers[run.parent.row] += static_cast<uint32_t>(kept);
        }
    // Into the pool rows through the memory (the pool's columns may live on a device).
    identityColumns(type, table, b.scattered);
    s_.scatter(b.scattered, first, b.poolRows);
    for (size_t s : info.zeroedState)  // (what init sets is not)
        for (int c = 0; c < o.state[s].type.width; ++c)
            s_.memory.clear(table[static_cast<size_t>(info.updateLayout.stateOffset[s] + c)], first, n);
}

// A batch's columns that identify its objects in their pool rows — creation times, ids,
// kept parameters — each with the pool's column it goes to.
void Creation::identityColumns(size_t type, const std::vector<Buffer>& table,
                               std::vector<std::pair<Buffer, Buffer>>& columns) const {
    const Pool& pool = s_.pools[type];
    const ir::Object& o = pool.object();
    const ColumnLayout& layout = s_.types[type].updateLayout;
    columns.assign({{table[ColumnLayout::kCreated], pool.created}, {table[ColumnLayout::kIds], pool.ids}});
    for (size_t p = 0; p < o.params.size(); ++p)
        if (pool.paramColumn[p] >= 0)
            for (int c = 0; c < o.params[p].type.width; ++c)
                columns.push_back({table[static_cast<size_t>(layout.paramOffset[p] + c)],
                                   pool.params.column(static_cast<size_t>(pool.paramColumn[p]), static_cast<size_t>(c))});
}

// At creation: init (the state, the bursts' sizes) and the exports, at each object's
// creation time with dt 0 (a per-row clock, the shape of the first update's); the state
// at creation kept for the bursts.
void Creation::atCreation(size_t type, Batch& b, size_t n) {
    const TypeInfo& info = s_.types[type];
    const ir::Object& o = s_.module.objects[type];
    const size_t first = b.first, end = first + n;
    const std::vector<Buffer>& table = b.updateTable;
    auto* mask = s_.host<uint8_t>(b.columns.at(kMask, Elem::U8, end));
    auto* created = s_.host<double>(table[ColumnLayout::kCreated]);
    Buffer zero = b.columns.at(kZero, Elem::F32, end);
    std::memset(s_.host<float>(zero) + first, 0, n * sizeof(float));
    auto atCreation = [&](const ir::Kernel& kernel, const ColumnLayout& layout, std::vector<Buffer>& t, Clock::Source dt) {
        t[ColumnLayout::kNow] = t[ColumnLayout::kCreated];
        t[ColumnLayout::kDt] = zero;
        RowsLaunch launch;
        launch.object = &o;
        launch.kernel = &kernel;
        launch.layout = &layout;
        launch.columns = t;
        launch.mask = b.columns.at(kMask, Elem::U8, end);
        launch.clock = {Clock::Source::PerRow, dt, 0, 0, true};
        launch.externs = s_.externs.data();
        launch.uniformKernel = s_.uniformKernel(type, kernel);
        launch.seed = s_.options.seed;
        launch.draw = kCreationDraw;
        s_.gatherParents(type, layout, t, mask, first, end, 0, created, b.poolRows.data(), first);
        runBatch(launch, first, end, type);
    };
    // (init at a uniform dt of 0; the exports at the clock of their other per-row launches)
    if (info.init) atCreation(*info.init, b.initLayout, b.initTable, Clock::Source::Uniform);
    if (info.exports) atCreation(*info.exports, info.exportsLayout, b.exportsTable, Clock::Source::PerRow);
    if (info.bursts)  // bursts read the state at creation, after the first update changed it
        for (size_t s = 0; s < o.state.size(); ++s)
            for (int c = 0; c < o.state[s].type.width; ++c) {
                auto column = static_cast<size_t>(info.updateLayout.stateOffset[s] + c);
                for (size_t site = 0; site < o.emits.size(); ++site)
                    if (!b.burstTables[site].empty()) {
                        s_.memory.copy(table[column], first, b.burstTables[site][column], first, n);
                        break;
                    }
            }
}

// A launch over rows [first, end) of a batch, in chunks (on several threads where the
// backend allows).
void Creation::runBatch(const RowsLaunch& launch, size_t first, size_t end, size_t type, LateKills* late) {
    std::atomic<uint64_t> unstable = 0;
    if (late) s_.ledger.resizeParts(*late, s_.chunkCount(end - first));
    s_.forChunks(first, end, [&](size_t c, size_t begin, size_t stop) {
        RowsLaunch part = launch;
        part.begin = begin;
        part.end = stop;
        part.late = late != nullptr;
        RowsResult result = s_.backend.run(part);
        if (result.unstable) unstable += result.unstable;
        if (late) s_.ledger.record(late->parts[c], result, launch.columns[ColumnLayout::kKill], begin, stop);
    });
    s_.typeStats[type].unstable += unstable;
}

// The first update of a batch's objects, from their creation to t1, in sub-steps no longer
// than @step; then each object's bursts, death or emissions, in queue order.
void Creation::firstUpdate(size_t type, Batch& b, size_t n, size_t allocated, double t1) {
    const TypeInfo& info = s_.types[type];
    const size_t first = b.first, end = first + n;
    const std::vector<Buffer>& table = b.updateTable;
    const auto* mask = s_.view<uint8_t>(b.columns.at(kMask, Elem::U8, end));
    const auto* created = s_.view<double>(table[ColumnLayout::kCreated]);
    b.spans.assign(n, 0);
    b.subSteps.assign(n, 1);
    std::atomic<uint32_t> most = 1;
    std::atomic<uint64_t> capped = 0;
    s_.forRows(0, n, [&](size_t begin, size_t end) {
        uint32_t chunkMost = 1;
        uint64_t chunkCapped = 0;
        for (size_t r = begin; r < end; ++r) {
            size_t i = first + r;
            if (!mask[i]) continue;
            double span = t1 - created[i];
            b.spans[r] = span;
            b.subSteps[r] = subStepCount(span, info.stepLimit, chunkCapped);
            chunkMost = std::max(chunkMost, b.subSteps[r]);
        }
        capped += chunkCapped;
        for (uint32_t m = most.load(); chunkMost > m && !most.compare_exchange_weak(m, chunkMost);) {
        }
    });
    s_.typeStats[type].cappedSubSteps += capped;
    // In queue order: `each(r, ordinal)` for the objects created, with the accounting of
    // rows allocated for the objects after them — as they leave the queue (an update, a
    // first sub-step); at a later sub-step every object of the batch is there, and what
    // they emit into their own type sees the pool's free rows alone (as where the memory
    // decides: Creation::createInMemory).
    auto inOrder = [&](bool leaveQueue, auto each) {
        size_t ordinal = 0;
        for (size_t r = 0; r < n; ++r) {
            if (leaveQueue) --queued_[type];
            if (b.poolRows[r] == kSkipRow) continue;
            pending_[type] = leaveQueue ? allocated - 1 - ordinal++ : 0;
            each(r);
        }
        pending_[type] = 0;
    };
    if (most == 1) {
        // Deaths nobody looks at before the end of the step are taken then (LateKills);
        // drawing as the step goes shows only the objects alive after their first update,
        // whether at their creation (after their type's update) or in that update (they
        // were created before it): it takes them at once.
        std::optional<LateKills> late;
        if (info.late && !s_.work[type].inStep.on) late.emplace(s_.ledger.fresh(type));
        // One update to t1: dt is each object's age then (Clock::Source::SinceCreated).
        advance(type, b, n, kMask, {Clock::Source::Uniform, Clock::Source::SinceCreated, t1, 0, false},
                late ? &*late : nullptr);
        if (info.bursts || info.updateEmits) {
            inOrder(true, [&](size_t r) {
                queueBursts(type, b, r);
                if (!late) killOrEmit(type, b, r, b.spans[r], t1);
            });
        } else {  // they emit nothing: no room to account for, only their kills in queue order
            queued_[type] -= n;
            if (!late && info.kills) {  // (listed in queue order, then frozen on every thread)
                const auto* kill = s_.view<uint8_t>(b.updateTable[ColumnLayout::kKill]);
                std::vector<uint32_t>& rows = b.killRows;
                std::vector<double>& at = b.killAt;
                rows.clear();
                at.clear();
                for (size_t r = 0; r < n; ++r)
                    if (b.poolRows[r] != kSkipRow && kill[first + r]) {
                        rows.push_back(b.poolRows[r]);
                        at.push_back(t1 - b.spans[r]);
                    }
                s_.ledger.kill(type, rows, at);
            }
        }
        if (late) {
            late->type = type;
            late->t1 = t1;
            late->first = first;
            late->poolRows = b.poolRows;
            late->spans = b.spans;
            s_.ledger.defer(std::move(*late));
        }
        return;
    }
    // Sub-steps: every object through its own, the k-th of each at once; each object's
    // bursts at creation just before its first sub-step's emissions, as in one update.
    auto* stepMask = s_.host<uint8_t>(b.columns.at(kStepMask, Elem::U8, end));
    auto* now = s_.host<double>(table[ColumnLayout::kNow]);
    auto* dt = s_.host<float>(table[ColumnLayout::kDt]);
    const Pool& pool = s_.pools[type];
    for (uint32_t k = 1; k <= most; ++k) {
        for (size_t r = 0; r < n; ++r) {
            size_t i = first + r;
            uint32_t steps = b.subSteps[r];
            stepMask[i] = mask[i] && k <= steps && pool.status(b.poolRows[r]) == Status::Alive;
            if (!stepMask[i]) continue;
            now[i] = subStepEnd(t1, b.spans[r], k, steps);
            dt[i] = static_cast<float>(b.spans[r] / steps);
        }
        advance(type, b, n, kStepMask, {Clock::Source::PerRow, Clock::Source::PerRow, 0, 0, false});
        inOrder(k == 1, [&](size_t r) {
            if (k == 1) queueBursts(type, b, r);
            if (stepMask[first + r]) killOrEmit(type, b, r, b.spans[r] / b.subSteps[r], now[first + r]);
        });
        // (What it emitted read its values as of this sub-step: before the next moves it on.)
        if (info.updateEmits && k < most) runSpawns();  // (nothing queued: nothing run)
    }
}

// One update of the batch rows `maskColumn` selects, at their own clocks, then their
// exports (those not killed), then the state and exports to their pool rows.
void Creation::advance(size_t type, Batch& b, size_t n, size_t maskColumn, const Clock& clock, LateKills* late) {
    const TypeInfo& info = s_.types[type];
    const ir::Object& o = s_.module.objects[type];
    const size_t first = b.first, end = first + n;
    std::vector<Buffer>& table = b.updateTable;
    Buffer maskBuffer = b.columns.at(maskColumn, Elem::U8, end);
    auto* mask = s_.host<uint8_t>(maskBuffer);
    const double* now = clock.now == Clock::Source::PerRow ? s_.view<double>(table[ColumnLayout::kNow]) : nullptr;
    auto launchOn = [&](const ir::Kernel& kernel, const ColumnLayout& layout, std::vector<Buffer>& t, Buffer m,
                        LateKills* kills) {
        t[ColumnLayout::kNow] = table[ColumnLayout::kNow];
        t[ColumnLayout::kDt] = table[ColumnLayout::kDt];
        RowsLaunch launch;
        launch.object = &o;
        launch.kernel = &kernel;
        launch.layout = &layout;
        launch.columns = t;
        launch.mask = m;
        launch.clock = clock;
        launch.externs = s_.externs.data();
        launch.uniformKernel = s_.uniformKernel(type, kernel);
        launch.seed = s_.options.seed;
        launch.draw = static_cast<uint32_t>(s_.step);
        if (kills) {  // its kills cleared in the pool's alive mask (Backend::clearsKilled), after the
                      // host has set the new rows' there: a later sync does not undo them
            s_.pools[type].syncMasks();
            launch.aliveMask = s_.pools[type].alive.column;
            launch.aliveRows = b.poolRows;
            launch.aliveRowsFirst = first;
        }
        s_.gatherParents(type, layout, t, s_.host<uint8_t>(m), first, end, clock.nowValue, now, b.poolRows.data(), first);
        runBatch(launch, first, end, type, kills);
    };
    launchOn(*info.update, info.updateLayout, table, maskBuffer, late);
    if (info.exports) {
        Buffer exportMask = b.columns.at(kExportMask, Elem::U8, end);
        auto* alive = s_.host<uint8_t>(exportMask);
        const auto* kill = s_.view<uint8_t>(table[ColumnLayout::kKill]);
        s_.forRows(first, end, [&](size_t begin, size_t stop) {
            for (size_t i = begin; i < stop; ++i) alive[i] = mask[i] && !(info.kills && kill[i]);
        });
        launchOn(*info.exports, info.exportsLayout, b.exportsTable, exportMask, nullptr);
    }
    Pool& pool = s_.pools[type];
    std::vector<std::pair<Buffer, Buffer>>& columns = b.scattered;
    columns.clear();
    for (size_t s = 0; s < o.state.size(); ++s)
        for (int c = 0; c < o.state[s].type.width; ++c)
            columns.push_back({table[static_cast<size_t>(info.updateLayout.stateOffset[s] + c)],
                               pool.state.column(s, static_cast<size_t>(c))});
    for (size_t e = 0; e < o.exports.size(); ++e)
        for (int c = 0; c < o.exports[e].type.width; ++c)
            columns.push_back({b.exportsTable[static_cast<size_t>(info.exportsLayout.exportOffset[e] + c)],
                               pool.exports.column(e, static_cast<size_t>(c))});
    s_.scatter(columns, first, b.poolRows);
}

void Creation::queueBursts(size_t type, Batch& b, size_t r) {
    const ir::Object& o = s_.module.objects[type];
    size_t i = b.first + r;
    const auto* created = s_.view<double>(b.updateTable[ColumnLayout::kCreated]);
    for (size_t site = 0; site < o.emits.size(); ++site) {
        if (!o.emits[site].atCreation()) continue;
        auto column = static_cast<size_t>(b.initLayout.emitCount(static_cast<int>(site)));
        float size = b.initTable.empty() ? 0 : s_.view<float>(b.initTable[column])[i];
        RateEmission burst = rt::burst(size, created[i]);
        s_.stats.invalidEmissions += burst.invalid;
        s_.stats.clampedEmissions += burst.clamped;
        if (burst.children == 0) continue;
        Emitter e{type, b.poolRows[r], b.burstTables[site], static_cast<uint32_t>(i), created[i], true};
        queueChildren(e, static_cast<int>(site), burst.children, burst.perEvent, burst.firstTime, burst.spacing);
    }
}

void Creation::killOrEmit(size_t type, Batch& b, size_t r, double dt, double t1) {
    const TypeInfo& info = s_.types[type];
    const ir::Object& o = s_.module.objects[type];
    size_t i = b.first + r;
    uint32_t row = b.poolRows[r];
    bool dying = info.kills && s_.view<uint8_t>(b.updateTable[ColumnLayout::kKill])[i];
    if (dying) s_.ledger.kill(type, row, t1 - dt);
    if (!info.updateEmits || (dying && !info.emitsWhenKilled)) return;
    rate_.assign(o.emits.size(), 0);
    count_.assign(o.emits.size(), 1);
    for (size_t s = 0; s < o.emits.size(); ++s) {
        auto site = static_cast<int>(s);
        if (info.rated[s]) rate_[s] = s_.view<float>(b.updateTable[static_cast<size_t>(info.updateLayout.emitRate(site))])[i];
        if (info.counted[s]) count_[s] = s_.view<float>(b.updateTable[static_cast<size_t>(info.updateLayout.emitCount(site))])[i];
    }
    emitInUpdate({type, row, {}, row, t1, false}, rate_, count_, dt, t1, dying);
}

}  // namespace psys::rt::detail
