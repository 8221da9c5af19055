// The System: construction, the host API, a step from end to end, kills and freeing.
// Updates and drawing are in system_update.cpp, creation in system_create.cpp.
#include "rt/system.h"

#include <chrono>
#include <cmath>
#include <cstdlib>

#include <fmt/format.h>

#include "rt/rng.h"
#include "rt/system_support.h"

namespace psys::rt {

using ir::KernelKind;
using ir::YieldKind;
using detail::Clock;
using detail::finite;
using detail::seconds;

System::System(ir::Module module, Backend& backend, SystemOptions options)
    : module_(std::move(module)), backend_(backend), options_(options) {
    for (const ir::Object& o : module_.objects) {
        size_t capacity = o.attributes.capacity ? static_cast<size_t>(*o.attributes.capacity) : options_.capacity;
        pools_.emplace_back(o, capacity);
        stepLimit_.push_back(o.attributes.step);
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
