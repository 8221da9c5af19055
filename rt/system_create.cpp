// Creating objects: the queue of objects asked for, creation in batches
// (createBatch) and one by one (create), and what triggers and the start emit.
#include "rt/system.h"

#include <algorithm>
#include <cmath>

#include "rt/rng.h"
#include "rt/system_support.h"

namespace psys::rt {

using ir::KernelKind;
using ir::YieldKind;
using detail::validCount;

// Queues `count` children of emit site `site`, `perEvent` at a time; the k-th event is at
// firstTime + k·spacing (spacing 0: all at once). Beyond the target's free capacity the
// rest are dropped and counted, without work per dropped child.
void System::queueChildren(size_t type, uint32_t row, int site, uint64_t count, uint64_t perEvent, double firstTime,
                           double spacing, double evalTime, bool first) {
    Pool& pool = pools_[type];
    const ir::EmitSite& emit = pool.object().emits[static_cast<size_t>(site)];
    size_t target = static_cast<size_t>(module_.objectIndex(emit.target));
    size_t free = pools_[target].free() + pending_[target];
    size_t room = free > queued_[target] ? free - queued_[target] : 0;
    uint64_t kept = std::min<uint64_t>(count, room);
    typeStats_[target].dropped += count - kept;
    if (kept == 0) return;
    const ir::Kernel* spawn = pool.object().kernel(KernelKind::Spawn, site);
    Handle parent = parentType_[target] == static_cast<int>(type) ? pool.handle(row) : Handle{};
    size_t params = pools_[target].paramColumn.size();
    size_t base = queueArgs_.size();
    queueArgs_.resize(base + static_cast<size_t>(kept) * params);
    if (spawn) {
        KernelInputs in = inputs(type, row, evalTime, static_cast<float>(lastDt_), first, params_, state_);
        in.uniforms = uniforms(type, *spawn, in);
        backend_.runChildren(*spawn, in, nextId_, static_cast<size_t>(kept), queueArgs_.data() + base, params);
    }
    for (uint64_t k = 0; k < kept; ++k) {
        queue_.push_back({target, base + static_cast<size_t>(k) * params, parent,
                          firstTime + static_cast<double>(k / perEvent) * spacing, nextId_++});
        ++queued_[target];
    }
}

// Creates one object at c.time and advances it to t1: init, its bursts, its exports, and
// a first update of the rest of the step.
void System::create(const Creation& c, double t1) {
    Pool& pool = pools_[c.type];
    auto allocated = pool.allocate();
    if (!allocated) {
        ++typeStats_[c.type].dropped;
        return;
    }
    uint32_t row = *allocated;
    const ir::Object& o = pool.object();
    ++typeStats_[c.type].created;
    pool.created[row] = c.time;
    pool.id[row] = c.id;
    pool.parent[row] = c.parent;
    if (c.parent.valid()) ++pools_[static_cast<size_t>(parentType_[c.type])].readers[c.parent.row];
    // A copy: creating may queue more, and move the queue's arguments.
    std::vector<Value>& args = createArgs_;
    args.assign(queueArgs_.begin() + static_cast<std::ptrdiff_t>(c.args),
                queueArgs_.begin() + static_cast<std::ptrdiff_t>(c.args + pool.paramColumn.size()));
    for (size_t i = 0; i < pool.paramColumn.size(); ++i)
        if (pool.paramColumn[i] >= 0) pool.params.set(static_cast<size_t>(pool.paramColumn[i]), row, args[i]);
    for (size_t i = 0; i < pool.state.count(); ++i) pool.state.set(i, row, Value{});

    std::vector<double>& bursts = bursts_;
    bursts.assign(o.emits.size(), 0);
    if (const ir::Kernel* init = o.kernel(KernelKind::Init)) {
        KernelInputs in = inputs(c.type, row, c.time, 0, true, params_, state_);
        in.params = args.data();  // every parameter, kept or not
        runKernel(c.type, row, *init, in);
        for (size_t i = 0; i < init->yields.size(); ++i) {
            const ir::Yield& y = init->yields[i];
            if (y.kind == YieldKind::StateNext) pool.state.set(static_cast<size_t>(y.index), row, yields_[i]);
            if (y.kind == YieldKind::EmitCount)
                bursts[static_cast<size_t>(y.index)] = std::floor(validCount(yields_[i].f[0], stats_.invalidEmissions));
        }
    }
    if (const ir::Kernel* ek = o.kernel(KernelKind::Exports)) {
        KernelInputs in = inputs(c.type, row, c.time, 0, true, params_, state_);
        runKernel(c.type, row, *ek, in);
        for (size_t i = 0; i < ek->yields.size(); ++i)
            pool.exports.set(static_cast<size_t>(ek->yields[i].index), row, yields_[i]);
    }
    for (size_t s = 0; s < o.emits.size(); ++s)
        if (!o.emits[s].rate && bursts[s] >= 1)
            queueChildren(c.type, row, static_cast<int>(s), static_cast<uint64_t>(std::min(bursts[s], 1e18)), 1, c.time,
                          0, c.time, true);
    update(c.type, row, t1 - c.time, t1);
}

// Creates the queued objects in queue order (and those their creation queues). Runs of
// one type that can be created in batches are; the rest one by one.
void System::drain(double t1) {
    for (size_t i = 0; i < queue_.size();) {
        size_t type = queue_[i].type;
        if (batches_[type].createInBatches) {
            size_t end = i + 1;
            while (end < queue_.size() && queue_[end].type == type) ++end;
            createBatch(type, i, end, t1);
            i = end;
            continue;
        }
        Creation c = queue_[i];  // a copy: creating may queue more
        --queued_[c.type];
        create(c, t1);
        ++i;
    }
    queue_.clear();
    queueArgs_.clear();
}

// Creates queue_[from, to), all of one type, as `create` would one by one: the rows are
// allocated in order, the init kernel and the first update run over all of them at once
// (on scratch columns, where every parameter has a column, kept or not), and kills and
// emissions follow object by object in queue order. While an object emits, the rows
// allocated for the objects after it count as free, as they still are in `create`.
void System::createBatch(size_t type, size_t from, size_t to, double t1) {
    Pool& pool = pools_[type];
    PoolBatch& b = batches_[type];
    const ir::Object& o = pool.object();
    b.newRows.clear();
    b.newQueueIndex.clear();
    for (size_t q = from; q < to; ++q) {
        auto row = pool.allocate();
        if (!row) {
            ++typeStats_[type].dropped;
            continue;
        }
        b.newRows.push_back(*row);
        b.newQueueIndex.push_back(q);
    }
    size_t n = b.newRows.size();
    // The queue entries leave the queue one by one below, as objects are created in order.
    if (n == 0) {
        queued_[type] -= to - from;
        return;
    }
    typeStats_[type].created += n;

    // Scratch columns in the layout's positions.
    const BatchLayout& layout = b.update;
    b.newColumns.resize(static_cast<size_t>(layout.total));
    b.newTable.assign(static_cast<size_t>(layout.total), nullptr);
    for (int column = BatchLayout::kFirstColumn; column < layout.total; ++column) {
        auto& c = b.newColumns[static_cast<size_t>(column)];
        c.assign(n, 0.0f);
        b.newTable[static_cast<size_t>(column)] = c.data();
    }
    b.newCreated.resize(n);
    b.newIds.resize(n);
    b.newKill.assign(n, 0);
    b.newMask.assign(n, 1);
    b.newTable[BatchLayout::kCreated] = b.newCreated.data();
    b.newTable[BatchLayout::kIds] = b.newIds.data();
    b.newTable[BatchLayout::kKill] = b.newKill.data();
    for (size_t r = 0; r < n; ++r) {
        const Creation& c = queue_[b.newQueueIndex[r]];
        uint32_t row = b.newRows[r];
        pool.created[row] = c.time;
        pool.id[row] = c.id;
        pool.parent[row] = c.parent;
        b.newCreated[r] = c.time;
        b.newIds[r] = c.id;
        for (size_t p = 0; p < o.params.size(); ++p) {
            const Value& v = queueArgs_[c.args + p];
            for (int k = 0; k < o.params[p].type.width; ++k)
                b.newColumns[static_cast<size_t>(layout.paramOffset[p] + k)][r] = v.f[static_cast<size_t>(k)];
            if (pool.paramColumn[p] >= 0) pool.params.set(static_cast<size_t>(pool.paramColumn[p]), row, v);
        }
    }

    RowBatch batch;
    batch.mask = b.newMask.data();
    batch.columns = b.newTable.data();
    batch.externs = externs_.data();
    batch.seed = options_.seed;
    auto runAll = [&](const ir::Kernel& kernel, const RowBatch& all) {
        forChunks(n, [&](size_t c) {
            RowBatch part = all;
            part.begin = c * kRowsPerChunk;
            part.end = std::min(n, part.begin + kRowsPerChunk);
            backend_.runRows(o, kernel, layout, part);
        });
    };
    if (const ir::Kernel* init = o.kernel(KernelKind::Init)) {
        RowBatch in = batch;
        in.mode = RowsMode::Init;
        in.draw = kCreationDraw;
        runAll(*init, in);
    }
    RowBatch first = batch;
    first.mode = RowsMode::FirstUpdate;
    first.time = t1;
    first.draw = static_cast<uint32_t>(step_);
    first.uniformKernel = o.kernel(KernelKind::UniformUpdate);
    runAll(*o.kernel(KernelKind::Update), first);

    for (size_t s = 0; s < o.state.size(); ++s)
        for (int k = 0; k < o.state[s].type.width; ++k) {
            const float* from = b.newColumns[static_cast<size_t>(layout.stateOffset[s] + k)].data();
            float* to = pool.state.data(s, static_cast<size_t>(k));
            for (size_t r = 0; r < n; ++r) to[b.newRows[r]] = from[r];
        }
    std::vector<float>& rate = rate_;
    std::vector<float>& count = count_;
    rate.assign(o.emits.size(), 0);
    count.assign(o.emits.size(), 1);
    size_t r = 0;
    for (size_t q = from; q < to; ++q) {
        --queued_[type];
        if (r == n || b.newQueueIndex[r] != q) continue;  // dropped at capacity
        uint32_t row = b.newRows[r];
        if (b.kills && b.newKill[r]) {
            kill(type, row);
        } else if (b.rateEmits) {
            for (size_t s = 0; s < o.emits.size(); ++s) {
                if (b.rated[s]) rate[s] = b.newColumns[static_cast<size_t>(layout.emitRate(static_cast<int>(s)))][r];
                if (b.counted[s]) count[s] = b.newColumns[static_cast<size_t>(layout.emitCount(static_cast<int>(s)))][r];
            }
            pending_[type] = n - 1 - r;
            emitAtRate(type, row, rate, count, t1 - b.newCreated[r], t1);
        }
        ++r;
    }
    pending_[type] = 0;
}


// Runs a trigger's (or the start's) kernel: once for the counts, then once per created
// object for its arguments, so each draws its own random numbers.
void System::emitFromKernel(const ir::Trigger& trigger, std::span<const Value> params, uint32_t objectId) {
    const ir::Kernel& k = trigger.kernel;
    KernelInputs in;
    in.params = params.data();
    in.externs = externs_.data();
    in.time = static_cast<float>(now_);
    in.seed = options_.seed;
    in.objectId = objectId;
    in.draw = static_cast<uint32_t>(step_);
    backend_.run(k, in, yields_);
    std::vector<double> counts(trigger.emits.size(), 0);
    for (size_t i = 0; i < k.yields.size(); ++i)
        if (k.yields[i].kind == YieldKind::EmitCount)
            counts[static_cast<size_t>(k.yields[i].index)] = std::floor(validCount(yields_[i].f[0], stats_.invalidEmissions));
    for (size_t s = 0; s < trigger.emits.size(); ++s) {
        size_t target = static_cast<size_t>(module_.objectIndex(trigger.emits[s].target));
        size_t room = pools_[target].free() > queued_[target] ? pools_[target].free() - queued_[target] : 0;
        auto kept = static_cast<uint64_t>(std::min(counts[s], static_cast<double>(room)));
        typeStats_[target].dropped += static_cast<uint64_t>(counts[s]) - kept;
        for (uint64_t n = 0; n < kept; ++n) {
            Creation c{target, queueArgs_.size(), {}, now_, nextId_++};
            queueArgs_.resize(queueArgs_.size() + pools_[target].paramColumn.size());
            in.childDraw = c.id;
            backend_.run(k, in, yields_);
            for (size_t i = 0; i < k.yields.size(); ++i)
                if (k.yields[i].kind == YieldKind::EmitArg && k.yields[i].index == static_cast<int>(s))
                    queueArgs_.at(c.args + static_cast<size_t>(k.yields[i].sub)) = yields_[i];
            ++queued_[target];
            queue_.push_back(c);
        }
    }
}


}  // namespace psys::rt
