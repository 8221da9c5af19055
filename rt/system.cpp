#include "rt/system.h"

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include "rt/rng.h"

namespace psys::rt {

using ir::KernelKind;
using ir::YieldKind;

namespace {

using Clock = std::chrono::steady_clock;
double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

// An emission count or rate from a kernel: NaN, infinite and negative values count as
// invalid and emit nothing.
double validCount(float x, uint64_t& invalid) {
    if (!std::isfinite(x) || x < 0) {
        ++invalid;
        return 0;
    }
    return x;
}

bool finite(const Value& v, int width) {
    for (int i = 0; i < width; ++i)
        if (!std::isfinite(v.f[static_cast<size_t>(i)])) return false;
    return true;
}

}  // namespace

System::System(ir::Module module, Backend& backend, SystemOptions options)
    : module_(std::move(module)), backend_(backend), options_(options) {
    for (const ir::Object& o : module_.objects) {
        size_t capacity = options_.capacity;
        if (auto it = o.attributes.find("capacity"); it != o.attributes.end())
            capacity = static_cast<size_t>(std::strtod(it->second.c_str(), nullptr));
        pools_.emplace_back(o, capacity);
        auto step = o.attributes.find("step");
        stepLimit_.push_back(step == o.attributes.end() ? 0 : std::strtod(step->second.c_str(), nullptr));
        parentType_.push_back(o.parent.empty() ? -1 : module_.objectIndex(o.parent));
        typeStats_.push_back({o.name, 0, 0, 0, 0, 0});
    }
    for (const ir::Extern& e : module_.externs) externs_.push_back({e.defaultValue, 0});
    render_.resize(pools_.size());
    renderStale_.assign(pools_.size(), true);
    queued_.assign(pools_.size(), 0);
    pending_.assign(pools_.size(), 0);
    uniformCache_.resize(pools_.size());
    for (const ir::Object& o : module_.objects) {
        PoolBatch b;
        const ir::Kernel* update = o.kernel(KernelKind::Update);
        b.update = batchLayout(o, *update);
        if (const ir::Kernel* ek = o.kernel(KernelKind::Exports)) b.exports = batchLayout(o, *ek);
        b.drawn.assign(4, false);
        if (const ir::Kernel* rk = o.kernel(KernelKind::Render)) {
            b.render = batchLayout(o, *rk);
            for (const ir::Yield& y : rk->yields) {
                if (y.kind == YieldKind::Visible) b.drawn[0] = true;
                if (y.kind == YieldKind::Position) b.drawn[1] = true;
                if (y.kind == YieldKind::Color) b.drawn[2] = true;
                if (y.kind == YieldKind::Size) b.drawn[3] = true;
            }
        }
        b.counted.assign(o.emits.size(), false);
        b.rated.assign(o.emits.size(), false);
        for (const ir::Yield& y : update->yields) {
            if (y.kind == YieldKind::Kill) b.kills = true;
            if (y.kind == YieldKind::EmitCount) b.counted[static_cast<size_t>(y.index)] = true;
            if (y.kind == YieldKind::EmitRate) b.rated[static_cast<size_t>(y.index)] = true;
        }
        bool bursts = false;
        for (const ir::EmitSite& e : o.emits) {
            b.rateEmits |= e.rate;
            bursts |= !e.rate;
        }
        b.createInBatches = options_.createInBatches && stepLimit_[batches_.size()] <= 0 && !o.kernel(KernelKind::Exports) && !bursts &&
                            parentType_[batches_.size()] < 0;
        batches_.push_back(std::move(b));
    }
    setThreads(options_.threads);
    backend_.prepare(plan());
}

System::~System() { backend_.forget(module_); }

void System::setThreads(unsigned threads) {
    options_.threads = threads;
    arena_ = std::make_unique<tbb::task_arena>(threads ? static_cast<int>(threads) : tbb::task_arena::automatic);
}

// The kernels this system runs object by object and the loops it runs over rows.
Backend::Plan System::plan() const {
    Backend::Plan plan;
    plan.objectKernels.push_back(&module_.start.kernel);
    for (const ir::Trigger& t : module_.triggers) plan.objectKernels.push_back(&t.kernel);
    for (size_t type = 0; type < pools_.size(); ++type) {
        const ir::Object& o = module_.objects[type];
        bool oneByOne = !batches_[type].createInBatches;
        bool subSteps = stepLimit_[type] > 0;
        for (const ir::Kernel& k : o.kernels) {
            switch (k.kind) {
                case KernelKind::Spawn: case KernelKind::UniformUpdate: case KernelKind::UniformRender:
                case KernelKind::UniformExports:
                    plan.objectKernels.push_back(&k);
                    break;
                case KernelKind::Init:
                    if (oneByOne) plan.objectKernels.push_back(&k);
                    else plan.loops.push_back({&o, &k, RowsMode::Init});
                    break;
                case KernelKind::Update:
                    if (oneByOne || subSteps) plan.objectKernels.push_back(&k);
                    plan.loops.push_back({&o, &k, RowsMode::Step});
                    if (!oneByOne) plan.loops.push_back({&o, &k, RowsMode::FirstUpdate});
                    break;
                case KernelKind::Exports:
                    if (oneByOne || subSteps) plan.objectKernels.push_back(&k);
                    plan.loops.push_back({&o, &k, RowsMode::Step});
                    break;
                case KernelKind::Render:
                    plan.loops.push_back({&o, &k, RowsMode::Step});
                    break;
                default:
                    break;
            }
        }
    }
    return plan;
}

// The `spawn`s run when the system is first used, so externs set before that apply.
void System::start() {
    if (started_) return;
    started_ = true;
    emitFromKernel(module_.start, {}, kStartObject);
    drain(now_);
}

int System::typeIndex(std::string_view name) const { return module_.objectIndex(std::string(name)); }

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

// Runs chunk(c) for every chunk of `rows` rows: on the arena's threads when the backend
// allows it and there is more than one chunk.
template <typename Chunk>
void System::forChunks(size_t rows, Chunk chunk) {
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
    KernelInputs context;
    context.dt = static_cast<float>(dt);
    context.time = static_cast<float>(t1);
    context.seed = options_.seed;
    RowBatch batch;
    batch.mask = pool.updatable.data();
    batch.columns = b.updateColumns.data();
    batch.externs = externs_.data();
    batch.uniforms = uniforms(type, update, context);
    batch.time = t1;
    batch.dt = static_cast<float>(dt);
    batch.seed = options_.seed;
    batch.draw = static_cast<uint32_t>(step_);
    RowBatch exportBatch = batch;
    if (exports) {
        b.exportMask.resize(rows);
        bindColumns(type, b.exports, b.exportScratch, b.exportColumns);
        exportBatch.mask = b.exportMask.data();
        exportBatch.columns = b.exportColumns.data();
        exportBatch.uniforms = uniforms(type, *exports, context);
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

void System::kill(size_t type, uint32_t row) {
    ++typeStats_[type].killed;
    pools_[type].freeze(row);  // no longer alive; freed at the end of the step if nobody reads it
    dying_.push_back({type, row});
}

// A reader of `parent` is gone; a frozen parent without readers is freed, and so on up.
void System::releaseReader(size_t childType, Handle parent) {
    int t = parentType_[childType];
    while (t >= 0 && parent.valid()) {
        Pool& pool = pools_[static_cast<size_t>(t)];
        if (!pool.matches(parent)) return;
        if (--pool.readers[parent.row] > 0 || pool.status(parent.row) != Status::Frozen) return;
        Handle up = pool.parent[parent.row];
        pool.release(parent.row);
        parent = up;
        childType = static_cast<size_t>(t);
        t = parentType_[childType];
    }
}

std::optional<std::string> System::step(double dt) {
    if (!std::isfinite(dt) || dt < 0) {
        ++stats_.rejectedSteps;
        return fmt::format("a step must be a finite, non-negative number of seconds, not {}", dt);
    }
    start();
    ++step_;
    lastDt_ = dt;
    double t1 = now_ + dt;
    for (Pool& pool : pools_) pool.beginStep();
    for (size_t type = 0; type < pools_.size(); ++type) {
        Pool& pool = pools_[type];
        if (stepLimit_[type] > 0 && dt > stepLimit_[type]) {
            // Sub-steps: object by object, each through all its sub-steps.
            auto start = Clock::now();
            for (uint32_t row = 0; row < pool.rows(); ++row)
                if (pool.updatable[row]) update(type, row, dt, t1);
            stats_.loopSeconds += seconds(start, Clock::now());
        } else {
            updatePool(type, dt, t1);
        }
        auto start = Clock::now();
        drain(t1);
        stats_.createSeconds += seconds(start, Clock::now());
    }
    now_ = t1;
    auto releasing = Clock::now();
    for (auto [type, row] : dying_) {
        Pool& pool = pools_[type];
        if (pool.status(row) != Status::Frozen || pool.readers[row] > 0) continue;
        Handle parent = pool.parent[row];
        pool.release(row);
        releaseReader(type, parent);
    }
    dying_.clear();
    stats_.emitSeconds += seconds(releasing, Clock::now());
    renderStale_.assign(pools_.size(), true);
    ++stats_.steps;
    return std::nullopt;
}

std::optional<std::string> System::setExtern(std::string_view name, std::span<const float> value) {
    int index = module_.externIndex(std::string(name));
    if (index < 0) return fmt::format("there is no extern `{}`", name);
    return setExtern(index, value);
}

std::optional<std::string> System::setExtern(int index, std::span<const float> value) {
    if (index < 0 || static_cast<size_t>(index) >= module_.externs.size())
        return fmt::format("there is no extern with handle {}", index);
    const ir::Extern& e = module_.externs[static_cast<size_t>(index)];
    const std::string& name = e.name;
    if (value.size() != static_cast<size_t>(e.type.width))
        return fmt::format("extern `{}` is {}: it takes {} value{}, not {}", name, e.type.str(), e.type.width,
                           e.type.width == 1 ? "" : "s", value.size());
    Value v;
    for (size_t i = 0; i < value.size(); ++i) v.f[i] = value[i];
    if (!finite(v, e.type.width)) ++stats_.nonFiniteExterns;
    externs_[static_cast<size_t>(index)] = v;
    ++externsVersion_;
    return std::nullopt;
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

std::optional<std::string> System::fire(std::string_view name, std::span<const float> args) {
    const ir::Trigger* trigger = nullptr;
    for (const ir::Trigger& t : module_.triggers)
        if (t.name == name) trigger = &t;
    if (!trigger) return fmt::format("there is no trigger `{}`", name);
    size_t width = 0;
    for (auto& p : trigger->params) width += static_cast<size_t>(p.type.width);
    if (args.size() != width)
        return fmt::format("trigger `{}` takes {} number{}, not {}", name, width, width == 1 ? "" : "s", args.size());
    std::vector<Value> params;
    size_t at = 0;
    for (auto& p : trigger->params) {
        Value v;
        for (int c = 0; c < p.type.width; ++c) v.f[static_cast<size_t>(c)] = args[at++];
        params.push_back(v);
    }
    start();
    emitFromKernel(*trigger, params, kTriggerObject);
    drain(now_);
    renderStale_.assign(pools_.size(), true);
    return std::nullopt;
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
    KernelInputs context;
    context.dt = static_cast<float>(lastDt_);
    context.time = static_cast<float>(now_);
    context.seed = options_.seed;
    RowBatch batch;
    batch.mask = b.aliveMask.data();
    batch.columns = b.renderColumns.data();
    batch.externs = externs_.data();
    batch.uniforms = uniforms(type, *k, context);
    batch.time = now_;
    batch.dt = static_cast<float>(lastDt_);
    batch.seed = options_.seed;
    batch.draw = static_cast<uint32_t>(step_);
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

Stats System::stats() const {
    Stats s = stats_;
    s.types = typeStats_;
    for (size_t t = 0; t < pools_.size(); ++t) {
        s.types[t].live = pools_[t].live();
        s.types[t].frozen = pools_[t].frozen();
    }
    return s;
}

}  // namespace psys::rt
