// Creating objects, the first half: the queue of objects asked for — by emitters at a
// rate, by bursts, by triggers and the start — with their arguments in staging columns,
// cut at each target's room; drained a batch at a time (rt/system_create.cpp).
#include "rt/system_create.h"

#include <algorithm>
#include <cmath>

#include "rt/rng.h"
#include "rt/system_support.h"

namespace psys::rt::detail {

using ir::YieldKind;

size_t Creation::stage(size_t type, size_t count) {
    Staging& st = staging_[type];
    size_t row = st.used;
    st.used += count;
    for (Buffer b : st.args)
        if (s_.memory.rows(b) < st.used) s_.memory.resize(b, std::max(st.used, 2 * s_.memory.rows(b)));
    return row;
}

void Creation::queueChildren(const Emitter& e, int site, uint64_t count, uint64_t perEvent, double firstTime,
                             double spacing) {
    const TypeInfo& info = s_.types[e.type];
    size_t target = info.emitTarget[static_cast<size_t>(site)];
    size_t free = s_.pools[target].free() + pending_[target];
    size_t room = free > queued_[target] ? free - queued_[target] : 0;
    uint64_t kept = std::min<uint64_t>(count, room);
    addSaturating(s_.typeStats[target].dropped, count - kept);
    if (kept == 0) return;
    Handle parent = s_.types[target].parentType == static_cast<int>(e.type) ? s_.pools[e.type].handle(e.row) : Handle{};
    size_t base = stage(target, static_cast<size_t>(kept));
    queueSpawn(e, site, s_.nextId, static_cast<size_t>(kept), base);
    enqueue({target, base, static_cast<size_t>(kept), parent, firstTime, spacing, perEvent, s_.nextId});
    s_.nextId += static_cast<uint32_t>(kept);
}

ChildrenLaunch* Creation::queueSpawn(const Emitter& e, int site, uint32_t firstChild, size_t count, size_t base,
                                     bool fromRecords) {
    const TypeInfo& info = s_.types[e.type];
    const ir::Kernel* spawn = info.spawn[static_cast<size_t>(site)];
    if (!spawn) return nullptr;
    size_t target = info.emitTarget[static_cast<size_t>(site)];
    const ColumnLayout& layout = info.spawnLayout[static_cast<size_t>(site)];
    if (spawnsUsed_ == spawns_.size()) spawns_.emplace_back();
    Spawn& queued = spawns_[spawnsUsed_++];
    queued.launch = {};
    queued.parents.clear();
    if (!fromRecords) s_.parentValues(e.type, e.row, layout, e.at, queued.parents);
    ChildrenLaunch& launch = queued.launch;
    launch.object = &s_.pools[e.type].object();
    launch.spawn = spawn;
    launch.layout = &layout;
    launch.columns = e.columns.empty() ? std::span<const Buffer>(s_.work[e.type].spawnTables[static_cast<size_t>(site)])
                                       : e.columns;
    launch.row = e.columns.empty() ? e.row : e.columnRow;
    launch.clock.nowValue = e.at;
    launch.clock.dtValue = static_cast<float>(s_.lastDt);
    launch.clock.first = e.first;
    launch.externs = s_.externs.data();
    launch.seed = s_.options.seed;
    launch.draw = e.first ? kCreationDraw : static_cast<uint32_t>(s_.step);
    launch.firstChild = firstChild;
    launch.count = count;
    launch.args = staging_[target].args;
    launch.argsFirst = base;
    return &launch;
}

void Creation::enqueue(const Run& run) {
    queued_[run.type] += run.count;
    if (s_.options.createInBatches) {
        queue_.push_back(run);
        return;
    }
    for (size_t k = 0; k < run.count; ++k)
        queue_.push_back({run.type, run.staging + k, 1, run.parent, run.time(k), 0, 1, run.id + static_cast<uint32_t>(k)});
}

void Creation::emitInUpdate(const Emitter& e, std::span<const float> rate, std::span<const float> count, double dt,
                            double t1, bool dying) {
    const Pool& pool = s_.pools[e.type];
    const ir::Object& o = pool.object();
    accumulators(e.type, accumulated_);
    rowEmissions_.resize(o.emits.size());
    emissionsOf(o, accumulated_.data(), e.row, rate, count, dt, t1, dying, rowEmissions_.data());
    queueEmissions(e, rowEmissions_);
}

void Creation::accumulators(size_t type, std::vector<double*>& out) const {
    const Pool& pool = s_.pools[type];
    out.assign(pool.object().emits.size(), nullptr);
    for (size_t site = 0; site < out.size(); ++site)
        if (pool.object().emits[site].rate()) out[site] = s_.host<double>(pool.emitted[site]);
}

void Creation::emissionsOf(const ir::Object& o, double* const* accumulated, uint32_t row, std::span<const float> rate,
                           std::span<const float> count, double dt, double t1, bool dying, RateEmission* out) {
    for (size_t site = 0; site < o.emits.size(); ++site) {
        out[site] = {};
        if (o.emits[site].whenKilled()) {  // (an edge's burst too: the update yields its count where it fired)
            out[site] = burst(count[site], t1);
        } else if (o.emits[site].rate() && !dying) {
            out[site] = rateEmission(accumulated[site][row], rate[site], count[site], dt, t1);
            accumulated[site][row] = out[site].accumulated;
        }
    }
}

void Creation::queueEmissions(const Emitter& e, std::span<const RateEmission> emissions) {
    for (size_t site = 0; site < emissions.size(); ++site) {
        const RateEmission& r = emissions[site];
        s_.stats.invalidEmissions += r.invalid;
        s_.stats.clampedEmissions += r.clamped;
        if (r.children) queueChildren(e, static_cast<int>(site), r.children, r.perEvent, r.firstTime, r.spacing);
    }
}

void Creation::emitFromKernel(const ir::Trigger& trigger, std::span<const Value> params, uint32_t objectId) {
    const ir::Kernel& k = trigger.kernel;
    ir::KernelInputs in;
    in.params = params.data();
    in.externs = s_.externs.data();
    in.time = static_cast<float>(s_.now);
    in.seed = s_.options.seed;
    in.objectId = objectId;
    in.draw = static_cast<uint32_t>(s_.step);
    s_.evaluator.run(k, in, yields_);
    std::vector<uint64_t> counts(trigger.emits.size(), 0);
    for (size_t i = 0; i < k.yields.size(); ++i)
        if (k.yields[i].kind == YieldKind::EmitCount)
            counts[static_cast<size_t>(k.yields[i].index)] =
                wholeCount(validCount(yields_[i].f[0], s_.stats.invalidEmissions), s_.stats.clampedEmissions);
    for (size_t site = 0; site < trigger.emits.size(); ++site) {
        auto target = static_cast<size_t>(s_.module.objectIndex(trigger.emits[site].target));
        Pool& pool = s_.pools[target];
        size_t room = pool.free() > queued_[target] ? pool.free() - queued_[target] : 0;
        uint64_t kept = std::min<uint64_t>(counts[site], room);
        addSaturating(s_.typeStats[target].dropped, counts[site] - kept);
        // The first column of each parameter among the staging columns.
        std::vector<size_t> column;
        size_t next = 0;
        for (const ir::Param& p : pool.object().params) {
            column.push_back(next);
            next += static_cast<size_t>(p.type.width);
        }
        size_t base = stage(target, static_cast<size_t>(kept));
        uint32_t id = s_.nextId;
        s_.nextId += static_cast<uint32_t>(kept);
        for (uint64_t n = 0; n < kept; ++n) {
            in.childDraw = id + static_cast<uint32_t>(n);
            s_.evaluator.run(k, in, yields_);
            for (size_t i = 0; i < k.yields.size(); ++i) {
                const ir::Yield& y = k.yields[i];
                if (y.kind != YieldKind::EmitArg || y.index != static_cast<int>(site)) continue;
                auto p = static_cast<size_t>(y.sub);
                for (int c = 0; c < pool.object().params[p].type.width; ++c)
                    s_.memory.write(staging_[target].args[column[p] + static_cast<size_t>(c)], base + n, 1,
                                    &yields_[i].f[static_cast<size_t>(c)]);
            }
        }
        if (kept) enqueue({target, base, static_cast<size_t>(kept), {}, s_.now, 0, 1, id});
    }
}

void Creation::runSpawns() {
    if (spawnsUsed_ == 0) return;
    launches_.clear();
    for (size_t i = 0; i < spawnsUsed_; ++i) {
        const Spawn& queued = spawns_[i];
        launches_.push_back(queued.launch);
        // (A launch from records reads each emitter's from the columns: gatherSpawnParents.)
        launches_.back().parents = queued.launch.records.valid() ? nullptr : queued.parents.data();
    }
    s_.backend.runChildren(launches_);
    spawnsUsed_ = 0;
}

// The queue is created a generation at a time — the runs queued before the drain, then
// those their creation queued, and so on — and a generation type by type, in the
// module's order of types, each type's runs in the order they came (a type's runs of one
// generation are adjacent in its staging columns, as one batch's must be). A run's
// objects took their ids as they were queued; what a generation's order decides is the
// order in which their creation emits — its objects' ids, rows and what their targets'
// room drops. So K emitters of several types create a batch of each type a step, not
// one a type and emitter (the campfire's dispatches grew with its fires), and where the
// memory decides an emitter's emissions (each target's objects one run, in the order of
// its sites: rt/system_create_rows.cpp) the generation is the same as where the host
// queues them an emitter row at a time — so an emitter of two types of emitters, or of
// an emitter in sub-steps beside another type, may be the memory's (decideRows).
void Creation::groupByType(size_t from, size_t to) {
    // A stable counting sort into vectors kept from drain to drain (std::stable_sort takes
    // a buffer from the heap at each call).
    groupStart_.assign(s_.pools.size() + 1, 0);
    for (size_t i = from; i < to; ++i) ++groupStart_[queue_[i].type + 1];
    for (size_t t = 1; t < groupStart_.size(); ++t) groupStart_[t] += groupStart_[t - 1];
    grouped_.resize(to - from);
    for (size_t i = from; i < to; ++i) grouped_[groupStart_[queue_[i].type]++] = queue_[i];
    std::copy(grouped_.begin(), grouped_.end(), queue_.begin() + static_cast<std::ptrdiff_t>(from));
}

void Creation::drain(double t1) {
    runSpawns();
    size_t generation = 0;                    // queue_[.., generation): this generation's runs
    for (size_t i = 0; i < queue_.size();) {  // (creating queues more at its end)
        if (i == generation) {
            generation = queue_.size();
            groupByType(i, generation);
        }
        size_t type = queue_[i].type;
        size_t end = i + 1;
        if (s_.options.createInBatches)
            while (end < generation && queue_[end].type == type) ++end;
        createBatch(type, i, end, t1);
        i = end;
    }
    queue_.clear();
    runsUsed_ = 0;
    for (Staging& st : staging_) st.used = 0;
}

}  // namespace psys::rt::detail
