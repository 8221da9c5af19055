// Updating and drawing: the loops over pools (updatePool, render), the inputs of kernels
// for one object, and the object-by-object path of types with @step.
#include "rt/system.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>

#include <tbb/parallel_for.h>

#include "rt/rng.h"
#include "rt/system_support.h"

namespace psys::rt {

using ir::KernelKind;
using ir::YieldKind;
using detail::Clock;
using detail::finite;
using detail::seconds;
using detail::validCount;

KernelInputs System::inputs(size_t type, uint32_t row, double at, float dt, bool first, std::vector<Value>& params,
                            std::vector<Value>& state) {
    Pool& pool = pools_[type];
    params.assign(pool.paramColumn.size(), Value{});
    for (size_t i = 0; i < params.size(); ++i)
        if (pool.paramColumn[i] >= 0) params[i] = pool.params.get(static_cast<size_t>(pool.paramColumn[i]), row);
    state.resize(pool.state.count());
    for (size_t i = 0; i < state.size(); ++i) state[i] = pool.state.get(i, row);
    KernelInputs in;
    in.params = params.data();
    in.state = state.data();
    in.externs = externs_.data();
    in.age = static_cast<float>(at - pool.created[row]);
    in.dt = dt;
    in.time = static_cast<float>(at);
    in.first = first;
    in.seed = options_.seed;
    in.objectId = pool.id[row];
    in.draw = first ? kCreationDraw : static_cast<uint32_t>(step_);
    if (parentType_[type] < 0) return in;  // no live parent reads: nothing more to set up
    auto ancestor = [this, type, row](int depth) { return this->ancestor(type, row, depth); };
    in.parentExport = [this, ancestor](int depth, int e) {
        auto [t, r] = ancestor(depth);
        return t < 0 ? Value{} : pools_[static_cast<size_t>(t)].exports.get(static_cast<size_t>(e), r);
    };
    in.parentAlive = [this, ancestor](int depth) {
        auto [t, r] = ancestor(depth);
        return t >= 0 && pools_[static_cast<size_t>(t)].status(r) == Status::Alive;
    };
    in.parentAge = [this, ancestor, at](int depth) {
        auto [t, r] = ancestor(depth);
        return t < 0 ? 0.0f : static_cast<float>(at - pools_[static_cast<size_t>(t)].created[r]);
    };
    return in;
}

// The ancestor `depth` levels up, or (type, row) = (-1, 0) when there is none.
std::pair<int, uint32_t> System::ancestor(size_t type, uint32_t row, int depth) const {
    int t = static_cast<int>(type);
    uint32_t r = row;
    for (int d = 0; d < depth; ++d) {
        Handle h = pools_[static_cast<size_t>(t)].parent[r];
        t = parentType_[static_cast<size_t>(t)];
        if (t < 0 || !h.valid() || !pools_[static_cast<size_t>(t)].matches(h)) return {-1, 0};
        r = h.row;
    }
    return {t, r};
}

// The values of `kernel`'s uniform kernel for the step context of `in`, computed again
// only when dt, time or an extern changed.
const Value* System::uniforms(size_t type, const ir::Kernel& kernel, const KernelInputs& in) {
    auto served = ir::uniformFor(kernel.kind);
    if (!served) return nullptr;
    const ir::Kernel* u = pools_[type].object().kernel(*served);
    if (!u) return nullptr;
    UniformCache& cache = uniformCache_[type][static_cast<size_t>(kernel.kind) - static_cast<size_t>(KernelKind::Update)];
    if (!cache.valid || cache.dt != in.dt || cache.time != in.time || cache.externs != externsVersion_) {
        KernelInputs ui;
        ui.externs = externs_.data();
        ui.dt = in.dt;
        ui.time = in.time;
        ui.seed = in.seed;
        std::vector<Value> values;
        backend_.run(*u, ui, values);
        cache.values.assign(values.size(), Value{});
        for (size_t i = 0; i < u->yields.size(); ++i) cache.values.at(static_cast<size_t>(u->yields[i].index)) = values[i];
        cache.valid = true;
        cache.dt = in.dt;
        cache.time = in.time;
        cache.externs = externsVersion_;
        ++stats_.uniformEvaluations;
    }
    return cache.values.data();
}

void System::runKernel(size_t type, uint32_t, const ir::Kernel& kernel, KernelInputs in) {
    in.uniforms = uniforms(type, kernel, in);
    backend_.run(kernel, in, yields_);
}

// Advances an object over (t1 − dt, t1]; with `@step(h)` in sub-steps no longer than h.
void System::update(size_t type, uint32_t row, double dt, double t1) {
    double h = stepLimit_[type];
    if (h <= 0 || dt <= h) {
        updateOnce(type, row, dt, t1);
        return;
    }
    double n = std::ceil(dt / h);
    double t0 = t1 - dt;
    for (double i = 1; i <= n; ++i) {
        updateOnce(type, row, dt / n, i == n ? t1 : t0 + dt * (i / n));
        if (pools_[type].status(row) != Status::Alive) return;
    }
}

// One update of an existing object over (t1 − dt, t1]: its next state, whether it dies,
// its exports and what it emits.
void System::updateOnce(size_t type, uint32_t row, double dt, double t1) {
    Pool& pool = pools_[type];
    const ir::Object& o = pool.object();
    const ir::Kernel* k = o.kernel(KernelKind::Update);
    KernelInputs in = inputs(type, row, t1, static_cast<float>(dt), false, params_, state_);
    runKernel(type, row, *k, in);
    bool killed = false;
    std::vector<float>& rate = rate_;
    std::vector<float>& count = count_;
    rate.assign(o.emits.size(), 0);
    count.assign(o.emits.size(), 1);
    for (size_t i = 0; i < k->yields.size(); ++i) {
        const ir::Yield& y = k->yields[i];
        switch (y.kind) {
            case YieldKind::StateNext: pool.state.set(static_cast<size_t>(y.index), row, yields_[i]); break;
            case YieldKind::Kill: killed = yields_[i].truth(); break;
            case YieldKind::EmitRate: rate[static_cast<size_t>(y.index)] = yields_[i].f[0]; break;
            case YieldKind::EmitCount: count[static_cast<size_t>(y.index)] = yields_[i].f[0]; break;
            default: break;
        }
    }
    if (killed) {
        kill(type, row);
        return;
    }
    if (const ir::Kernel* ek = o.kernel(KernelKind::Exports)) {
        KernelInputs post = inputs(type, row, t1, static_cast<float>(dt), false, params_, state_);
        runKernel(type, row, *ek, post);
        for (size_t i = 0; i < ek->yields.size(); ++i)
            pool.exports.set(static_cast<size_t>(ek->yields[i].index), row, yields_[i]);
    }
    emitAtRate(type, row, rate, count, dt, t1);
}

// Rate emitters: events fall where the accumulated rate crosses a whole number, so a
// stream is smooth within a step and a rate of 0.25/s emits at 4 s, 8 s, …
void System::emitAtRate(size_t type, uint32_t row, std::span<const float> rate, std::span<const float> count,
                        double dt, double t1) {
    Pool& pool = pools_[type];
    const ir::Object& o = pool.object();
    for (size_t s = 0; s < o.emits.size(); ++s) {
        if (!o.emits[s].rate) continue;
        double r = validCount(rate[s], stats_.invalidEmissions);
        double perEvent = std::floor(validCount(count[s], stats_.invalidEmissions));
        double before = pool.emitted[s][row];
        double total = before + r * dt;
        // A whole number reached by adding up rounded rates (0.25 · 1/60, 240 times) counts as reached.
        double events = std::floor(total + 1e-9);
        pool.emitted[s][row] = std::max(0.0, total - events);
        if (events < 1 || perEvent < 1) continue;
        double firstTime = (t1 - dt) + (1.0 - before) / r;
        double children = events * perEvent;
        queueChildren(type, row, static_cast<int>(s), static_cast<uint64_t>(std::min(children, 1e18)),
                      static_cast<uint64_t>(perEvent), firstTime, 1.0 / r, t1, false);
    }
}

// Points the column table of a batched kernel at the pool's columns and the scratch
// columns (emission rates and counts, gathered parent values).
void System::bindColumns(size_t type, const BatchLayout& layout, std::vector<std::vector<float>>& scratch,
                         std::vector<void*>& table) {
    Pool& pool = pools_[type];
    PoolBatch& b = batches_[type];
    const ir::Object& o = pool.object();
    size_t rows = pool.rows();
    table.assign(static_cast<size_t>(layout.total), nullptr);
    table[BatchLayout::kCreated] = pool.created.data();
    table[BatchLayout::kIds] = pool.id.data();
    table[BatchLayout::kKill] = b.kill.data();
    for (size_t s = 0; s < o.state.size(); ++s)
        for (int c = 0; c < o.state[s].type.width; ++c)
            table[static_cast<size_t>(layout.stateOffset[s] + c)] = pool.state.data(s, static_cast<size_t>(c));
    for (size_t p = 0; p < o.params.size(); ++p)
        if (pool.paramColumn[p] >= 0)
            for (int c = 0; c < o.params[p].type.width; ++c)
                table[static_cast<size_t>(layout.paramOffset[p] + c)] =
                    pool.params.data(static_cast<size_t>(pool.paramColumn[p]), static_cast<size_t>(c));
    for (size_t e = 0; e < o.exports.size(); ++e)
        for (int c = 0; c < o.exports[e].type.width; ++c)
            table[static_cast<size_t>(layout.exportOffset[e] + c)] = pool.exports.data(e, static_cast<size_t>(c));
    scratch.resize(static_cast<size_t>(layout.total - layout.emits));
    for (int column = layout.emits; column < layout.total; ++column) {
        auto& s = scratch[static_cast<size_t>(column - layout.emits)];
        s.resize(rows);
        table[static_cast<size_t>(column)] = s.data();
    }
}

// Fills the parent columns of a batched kernel for the masked rows of [begin, end).
void System::gatherParents(size_t type, const BatchLayout& layout, void* const* table, const uint8_t* mask,
                           size_t begin, size_t end, double at) const {
    for (const auto& p : layout.parentColumns) {
        for (size_t row = begin; row < end; ++row) {
            if (!mask[row]) continue;
            auto [t, r] = ancestor(type, static_cast<uint32_t>(row), p.depth);
            const Pool* parent = t < 0 ? nullptr : &pools_[static_cast<size_t>(t)];
            Value v;
            if (p.op == ir::Op::ParentExport && parent) v = parent->exports.get(static_cast<size_t>(p.exportIndex), r);
            if (p.op == ir::Op::ParentAlive) v = Value::boolean(parent && parent->status(r) == Status::Alive);
            if (p.op == ir::Op::ParentAge && parent) v = Value::scalar(static_cast<float>(at - parent->created[r]));
            for (int c = 0; c < p.width; ++c) static_cast<float*>(table[p.offset + c])[row] = v.f[static_cast<size_t>(c)];
        }
    }
}

// A batch of `kernel` over a type's pool for the step that ends at `time`: its uniform
// values, the externs, the seed and the draw of this step. The rows are set per chunk.
RowBatch System::stepBatch(size_t type, const ir::Kernel& kernel, const uint8_t* mask, const std::vector<void*>& columns,
                           double time, double dt) {
    KernelInputs context;
    context.dt = static_cast<float>(dt);
    context.time = static_cast<float>(time);
    context.seed = options_.seed;
    RowBatch batch;
    batch.mask = mask;
    batch.columns = columns.data();
    batch.externs = externs_.data();
    batch.uniforms = uniforms(type, kernel, context);
    batch.time = time;
    batch.dt = static_cast<float>(dt);
    batch.seed = options_.seed;
    batch.draw = static_cast<uint32_t>(step_);
    return batch;
}

// Runs chunk(c) for every chunk of `rows` rows: on the arena's threads when the backend
// allows it and there is more than one chunk.
void System::forChunks(size_t rows, const std::function<void(size_t)>& chunk) {
    size_t chunks = (rows + kRowsPerChunk - 1) / kRowsPerChunk;
    if (chunks > 1 && backend_.concurrent() && arena_->max_concurrency() > 1) {
        arena_->execute([&] { tbb::parallel_for(size_t{0}, chunks, chunk); });
    } else {
        for (size_t c = 0; c < chunks; ++c) chunk(c);
    }
}

// One update of every updatable object of a type, as `updateOnce` would do object by
// object: the update kernel and the exports kernel run over chunks of rows (on several
// threads where the backend allows), then kills and emissions follow in row order, so
// that ids, the queue and the free list come out the same with any number of threads.
void System::updatePool(size_t type, double dt, double t1) {
    Pool& pool = pools_[type];
    PoolBatch& b = batches_[type];
    const ir::Object& o = pool.object();
    const ir::Kernel& update = *o.kernel(KernelKind::Update);
    const ir::Kernel* exports = o.kernel(KernelKind::Exports);
    size_t rows = pool.rows();
    if (rows == 0 || pool.live() == 0) return;
    b.kill.resize(rows);
    bindColumns(type, b.update, b.updateScratch, b.updateColumns);
    RowBatch batch = stepBatch(type, update, pool.updatable.data(), b.updateColumns, t1, dt);
    RowBatch exportBatch = batch;
    if (exports) {
        b.exportMask.resize(rows);
        bindColumns(type, b.exports, b.exportScratch, b.exportColumns);
        exportBatch = stepBatch(type, *exports, b.exportMask.data(), b.exportColumns, t1, dt);
    }
    // Objects that only die (no rate emits) are found while their chunk is in cache.
    bool listKills = b.kills && !b.rateEmits;
    size_t chunks = (rows + kRowsPerChunk - 1) / kRowsPerChunk;
    if (listKills) b.killed.resize(chunks);
    auto chunk = [&](size_t c) {
        RowBatch part = batch;
        part.begin = c * kRowsPerChunk;
        part.end = std::min(rows, part.begin + kRowsPerChunk);
        gatherParents(type, b.update, part.columns, part.mask, part.begin, part.end, t1);
        backend_.runRows(o, update, b.update, part);
        if (listKills) {
            b.killed[c].clear();
            size_t row = part.begin;
            for (; row + 8 <= part.end; row += 8) {  // most objects live: eight flags at a time
                uint64_t flags;
                std::memcpy(&flags, b.kill.data() + row, sizeof flags);
                if (!flags) continue;
                for (size_t r = row; r < row + 8; ++r)
                    if (b.kill[r]) b.killed[c].push_back(static_cast<uint32_t>(r));
            }
            for (; row < part.end; ++row)
                if (b.kill[row]) b.killed[c].push_back(static_cast<uint32_t>(row));
        }
        if (!exports) return;
        for (size_t row = part.begin; row < part.end; ++row)
            b.exportMask[row] = pool.updatable[row] && !(b.kills && b.kill[row]);
        RowBatch post = exportBatch;
        post.begin = part.begin;
        post.end = part.end;
        gatherParents(type, b.exports, post.columns, post.mask, post.begin, post.end, t1);
        backend_.runRows(o, *exports, b.exports, post);
    };
    auto start = Clock::now();
    forChunks(rows, chunk);
    auto loopsDone = Clock::now();
    stats_.loopSeconds += seconds(start, loopsDone);
    struct Timer {
        Stats& stats;
        Clock::time_point start;
        ~Timer() { stats.emitSeconds += seconds(start, Clock::now()); }
    } timer{stats_, loopsDone};
    if (!b.kills && !b.rateEmits) return;
    if (listKills) {
        for (size_t c = 0; c < chunks; ++c)
            for (uint32_t row : b.killed[c]) kill(type, row);
        return;
    }
    std::vector<float>& rate = rate_;
    std::vector<float>& count = count_;
    rate.assign(o.emits.size(), 0);
    count.assign(o.emits.size(), 1);
    for (uint32_t row = 0; row < rows; ++row) {
        if (!pool.updatable[row]) continue;
        if (b.kills && b.kill[row]) {
            kill(type, row);
            continue;
        }
        if (!b.rateEmits) continue;
        for (size_t s = 0; s < o.emits.size(); ++s) {
            if (b.rated[s])
                rate[s] = static_cast<float*>(b.updateColumns[static_cast<size_t>(b.update.emitRate(static_cast<int>(s)))])[row];
            if (b.counted[s])
                count[s] = static_cast<float*>(b.updateColumns[static_cast<size_t>(b.update.emitCount(static_cast<int>(s)))])[row];
        }
        emitAtRate(type, row, rate, count, dt, t1);
    }
}

const std::vector<RenderPoint>& System::render(size_t type) {
    start();
    if (!renderStale_[type]) return render_[type];
    renderStale_[type] = false;
    auto& out = render_[type];
    out.clear();
    Pool& pool = pools_[type];
    PoolBatch& b = batches_[type];
    const ir::Kernel* k = pool.object().kernel(KernelKind::Render);
    size_t rows = pool.rows();
    if (!k || !b.drawn[0] || rows == 0) return out;
    b.aliveMask.resize(rows);
    bindColumns(type, b.render, b.renderScratch, b.renderColumns);
    RowBatch batch = stepBatch(type, *k, b.aliveMask.data(), b.renderColumns, now_, lastDt_);
    forChunks(rows, [&](size_t c) {
        RowBatch part = batch;
        part.begin = c * kRowsPerChunk;
        part.end = std::min(rows, part.begin + kRowsPerChunk);
        for (size_t row = part.begin; row < part.end; ++row)
            b.aliveMask[row] = pool.status(static_cast<uint32_t>(row)) == Status::Alive;
        gatherParents(type, b.render, part.columns, part.mask, part.begin, part.end, now_);
        backend_.runRows(pool.object(), *k, b.render, part);
    });
    auto column = [&](int offset) { return static_cast<const float*>(b.renderColumns[static_cast<size_t>(b.render.render + offset)]); };
    const float* visible = column(BatchLayout::kVisible);
    for (uint32_t row = 0; row < rows; ++row) {
        if (!b.aliveMask[row] || visible[row] == 0) continue;
        RenderPoint p{pool.id[row], {}, {}, 0};
        if (b.drawn[1])
            for (int c = 0; c < 3; ++c) p.position[static_cast<size_t>(c)] = column(BatchLayout::kPosition + c)[row];
        if (b.drawn[2])
            for (int c = 0; c < 4; ++c) p.color[static_cast<size_t>(c)] = column(BatchLayout::kColor + c)[row];
        if (b.drawn[3]) p.size = column(BatchLayout::kSize)[row];
        bool ok = true;
        for (float x : p.position) ok &= std::isfinite(x);
        for (float x : p.color) ok &= std::isfinite(x);
        ok &= std::isfinite(p.size);
        if (!ok) {
            ++stats_.nonFiniteRender;
            continue;
        }
        out.push_back(p);
    }
    return out;
}


}  // namespace psys::rt
