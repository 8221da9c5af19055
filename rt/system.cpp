// The System: the host API and the schedule of a step. The object store and what the
// parts share are rt/system_state.cpp; updating rt/system_update.cpp; creating
// rt/system_create.cpp; drawing rt/system_draw.cpp; hot reload rt/reload.cpp.
#include "rt/system.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include <fmt/format.h>

#include "rt/rng.h"
#include "rt/system_create.h"
#include "rt/system_draw.h"
#include "rt/system_support.h"
#include "rt/system_update.h"

namespace psys::rt {

using detail::finite;
using detail::seconds;
using detail::WallClock;
using Wait = detail::Ledger::Wait;
using ir::KernelKind;

// Every launch shape a system asks for (rt/system_create.cpp, rt/system_update.cpp,
// rt/system_draw.cpp): steps of existing objects at one clock; everything about objects
// being created (init and exports at their creation times, first updates and their
// exports) at per-row clocks.
Plan launchPlan(const ir::Module& module) {
    using S = Clock::Source;
    // Types created at a rate are created many at a time, step after step; the others (by
    // the start, bursts and triggers) now and then.
    std::set<std::string> streams;
    for (const ir::Object& o : module.objects)
        for (const ir::EmitSite& e : o.emits)
            if (e.rate()) streams.insert(e.target);
    // An instanced program's updates run at each instance's speed (per-row dt) in a step
    // where one is not 1 (rt/system_speeds.cpp).
    const bool instanced = module.instanced();
    Plan plan;
    for (const ir::Object& o : module.objects) {
        bool stream = streams.count(o.name) > 0;
        // A new object's first update (and its exports after it) runs to the step's end
        // with dt its age then; under @step, where it is longer than a sub-step, in
        // sub-steps at per-row clocks.
        bool subSteps = o.attributes.step > 0;
        for (const ir::Kernel& k : o.kernels) {
            switch (k.kind) {
                case KernelKind::Init:  // dt 0; one that sets nothing does not run (initKernel)
                    if (initKernel(o)) plan.rows.push_back({&o, &k, S::PerRow, S::Uniform, stream});
                    break;
                case KernelKind::Update:
                    plan.rows.push_back({&o, &k, S::Uniform, S::Uniform});
                    if (instanced) plan.rows.push_back({&o, &k, S::Uniform, S::PerRow});  // (instance speeds)
                    plan.rows.push_back({&o, &k, S::Uniform, S::SinceCreated, stream});
                    if (subSteps) plan.rows.push_back({&o, &k, S::PerRow, S::PerRow, stream});
                    break;
                case KernelKind::Exports:  // also at creation, at each object's creation time
                    plan.rows.push_back({&o, &k, S::Uniform, S::Uniform});
                    if (instanced) plan.rows.push_back({&o, &k, S::Uniform, S::PerRow});
                    plan.rows.push_back({&o, &k, S::PerRow, S::PerRow, stream});
                    plan.rows.push_back({&o, &k, S::Uniform, S::SinceCreated, stream});
                    break;
                case KernelKind::Render: plan.rows.push_back({&o, &k, S::Uniform, S::Uniform}); break;
                case KernelKind::Spawn: plan.children.push_back({&o, &k}); break;
                default: break;  // start, triggers and uniform kernels: evaluated on the host
            }
        }
    }
    return plan;
}

System::System(ir::Module module, Backend& backend, SystemOptions options)
    : state_(std::make_unique<detail::State>(std::move(module), backend, options)),
      creation_(std::make_unique<detail::Creation>(*state_)),
      drawing_(std::make_unique<detail::Drawing>(*state_)) {
    state_->schedule = detail::stepSchedule(*state_);
    backend.prepare(launchPlan(state_->module));
}

System::~System() {
    try {
        finish();  // a device's counts and kills, so that it keeps nothing for this system
    } catch (const std::exception&) {
        // a device that failed has nothing to give back
    }
    drawing_.reset();
    creation_.reset();
    state_->backend.forget(state_->module);
}

void System::reset() {
    finish();
    detail::State& old = *state_;
    Backend& backend = old.backend;
    SystemOptions options = old.options;
    std::vector<Value> externs = old.externs;  // (the host's values stay)
    // The module moves over whole: its kernels stay where they are, and the backend's
    // compiled functions for them with them — nothing is compiled again.
    // The new state is made before the old goes (what holds the old, drawing and creation,
    // goes first): a failure leaves a system that has no module, never a dangling one.
    auto fresh = std::make_unique<detail::State>(std::move(old.module), backend, options);
    drawing_.reset();
    creation_.reset();
    state_ = std::move(fresh);
    creation_ = std::make_unique<detail::Creation>(*state_);
    drawing_ = std::make_unique<detail::Drawing>(*state_);
    state_->schedule = detail::stepSchedule(*state_);
    // (Of the instances only the system's own is left, playing, where it was.)
    const size_t own = state_->module.externs.size() + (state_->module.instanced() ? 1 + state_->instanceValues() : 0);
    externs.resize(own);
    state_->externs = std::move(externs);
    if (state_->module.instanced()) {
        state_->externs[state_->module.externs.size()].f[0] = 1;
        state_->setLife(0, InstanceLife::Playing);
    }
    ++state_->externsVersion;
}

std::optional<std::string> System::prewarm(double seconds, double longest) {
    if (!std::isfinite(seconds) || seconds < 0)
        return fmt::format("prewarm: the time to run ahead is a finite, non-negative number of seconds, not {}", seconds);
    if (!std::isfinite(longest) || longest <= 0)
        return fmt::format("prewarm: the longest step is a finite, positive number of seconds, not {}", longest);
    if (seconds == 0) return std::nullopt;
    // Equal steps, as few as `longest` allows (no sliver of a last step).
    const double steps = std::ceil(seconds / longest);
    if (steps > 1e7) return fmt::format("prewarm: {} s in steps of {} s is {} steps: more than 10^7", seconds, longest, steps);
    const double dt = seconds / steps;
    for (double k = 0; k < steps; ++k)
        if (auto error = step(dt)) return "prewarm: " + *error;
    return std::nullopt;
}

void System::setThreads(unsigned threads) {
    state_->options.threads = threads;
    state_->parallel = std::make_unique<detail::Parallel>(threads);
}

double System::time() const { return state_->now; }
uint64_t System::stepCount() const { return state_->step; }
const ir::Module& System::module() const { return state_->module; }
const SystemOptions& System::options() const { return state_->options; }
const Pool& System::pool(size_t type) const { return state_->pools[type]; }
size_t System::typeCount() const { return state_->pools.size(); }
Backend& System::backend() const { return state_->backend; }
const Schedule& System::schedule() const { return state_->schedule; }
int System::typeIndex(std::string_view name) const { return state_->module.objectIndex(std::string(name)); }
int System::externHandle(std::string_view name) const { return state_->module.externIndex(std::string(name)); }

// The `spawn`s run when the system is first used, so externs set before that apply.
void System::start() {
    detail::State& s = *state_;
    if (s.started && s.reloadSpawns.empty()) return;
    if (!s.started) {
        s.started = true;
        // (An instanced program's: the system's own instance, unless the host killed it first.)
        if (!s.module.instanced()) creation_->emitFromKernel(s.module.start, {}, kStartObject);
        else if (s.instances[0].life == InstanceLife::Playing)
            creation_->emitFromKernel(s.module.start, std::vector<Value>{Value::scalar(0)}, kStartObject);
    } else {  // a reload's added spawns: the start with the others' counts left out
        ir::Trigger added = s.module.start;
        std::erase_if(added.kernel.yields, [&](const ir::Yield& y) {
            return y.kind == ir::YieldKind::EmitCount &&
                   std::find(s.reloadSpawns.begin(), s.reloadSpawns.end(), static_cast<size_t>(y.index)) ==
                       s.reloadSpawns.end();
        });
        s.reloadSpawns.clear();
        std::vector<Value> own;
        if (s.module.instanced()) own.push_back(Value::scalar(0));
        creation_->emitFromKernel(added, own, kStartObject);
    }
    creation_->drain(s.now);
    s.ledger.settle(Wait::No);
}

void System::finish() {
    state_->ledger.settle(Wait::Yes);
    drawing_->takeCounts();
}

// The executor of the schedule (rt/schedule.h) on any backend: phases [first, end) of a
// step, or of one of its sub-steps, over (t1 − dt, t1]; `last`: the sub-step ending the step,
// which ends at `stepEnd`.
void System::runPhases(size_t first, size_t end, double dt, double t1, bool last, double stepEnd) {
    detail::State& s = *state_;
    const std::vector<Phase>& phases = s.schedule.phases;
    for (size_t i = first; i < end; ++i) {
        const Phase& p = phases[i];
        auto type = static_cast<size_t>(p.type);
        auto start = WallClock::now();
        switch (p.kind) {
            case PhaseKind::Settle: s.ledger.settle(Wait::Yes); break;
            case PhaseKind::Ready:
                for (Pool& pool : s.pools) pool.beginStep();
                for (detail::TypeWork& work : s.work) work.taken = {};  // (the last step's: its Release freed them)
                break;
            case PhaseKind::Neighbours:
                s.foldNeighbours(type);
                s.stats.foldSeconds += seconds(start, WallClock::now());
                continue;
            case PhaseKind::SubSteps: {
                // Sub-steps of equal length, each a pass over the pool: an object killed in one
                // takes no more, and what it emits in each is queued in (sub-step, row) order.
                // (At the fastest instance's speed: none of its sub-steps is longer than the limit.)
                const double span = s.scaledStep ? dt * s.fastest : dt;
                uint32_t n = subStepCount(span, p.stepLimit, s.typeStats[type].cappedSubSteps);
                for (uint32_t k = 1; k <= n; ++k)
                    runPhases(i + 1, i + 1 + p.span, dt / n, subStepEnd(t1, dt, k, n), last && k == n, stepEnd);
                i += p.span;
                continue;
            }
            case PhaseKind::Update:
                detail::runUpdate(s, p, dt, t1, last);
                if (last) s.work[type].inStep.updated = true;
                s.stats.loopSeconds += seconds(start, WallClock::now());
                continue;
            case PhaseKind::Kills: detail::runKills(s, type, dt, t1); break;
            case PhaseKind::Emissions: detail::runEmissions(s, *creation_, type, dt, t1); break;
            case PhaseKind::Create:  // (after a sub-step too: its objects to the step's end)
                creation_->drain(stepEnd);
                s.stats.createSeconds += seconds(start, WallClock::now());
                continue;
            case PhaseKind::Release:
                s.now = t1;  // the time moves on
                s.ledger.endStep();
                break;
        }
        s.stats.emitSeconds += seconds(start, WallClock::now());
    }
}

std::optional<std::string> System::step(double dt) {
    detail::State& s = *state_;
    if (!std::isfinite(dt) || dt < 0) {
        ++s.stats.rejectedSteps;
        return fmt::format("a step must be a finite, non-negative number of seconds, not {}", dt);
    }
    // Past kLatestTime a double's time has steps of more than a microsecond, and ages
    // computed from it would lose the precision docs/runtime.md promises (at 1e308 it
    // becomes infinite): such a step is refused like a non-finite one.
    if (!(s.now + dt <= kLatestTime)) {
        ++s.stats.rejectedSteps;
        return fmt::format("a step of {} s from {} s would take the time past {} s (2^32 s, 136 years), where "
                           "ages stop being exact to the microsecond",
                           dt, s.now, kLatestTime);
    }
    start();
    // The schedule's first phase settles what the last step and triggers since left (a step
    // of no time too); then, unless no time passes, the rest. No time: no update runs, so
    // nothing moves, nothing is emitted, and no `prev` or `->` chain advances (it would count
    // updates, not time).
    runPhases(0, 1, dt, s.now + dt, true, s.now + dt);
    if (dt == 0) {
        ++s.stats.steps;
        return std::nullopt;
    }
    ++s.step;
    s.lastDt = dt;
    s.takeSpeeds();  // (after the last step's deaths are settled: they read its speeds)
    double t1 = s.now + dt;
    // The host drew after the last step: this one draws as it goes.
    bool drawing = s.options.drawInStep && drawing_->drewSinceStep() && s.backend.rendersInStep();
    drawing_->stepping();
    for (size_t type = 0; type < s.pools.size(); ++type)
        s.work[type].inStep = {drawing && s.types[type].render && s.types[type].drawn[0], false, false, 0, 0};
    // The rest of the schedule's phases: ready, per type, parents before children, its
    // update, kills and emissions (in sub-steps), what it queued created; release.
    runPhases(1, s.schedule.phases.size(), dt, t1, true, t1);
    s.now = t1;
    for (detail::TypeWork& w : s.work) {
        w.inStep.fresh = w.inStep.on;
        w.inStep.on = w.inStep.updated = false;
    }
    drawing_->invalidate(true);
    ++s.stats.steps;
    s.finishInstances();
    if (s.options.onFinished) {
        bool now = finished();
        if (now && !s.saidFinished) s.options.onFinished(*this);
        s.saidFinished = now;
    }
    return std::nullopt;
}

bool System::finished() const {
    detail::State& s = *state_;
    if (!s.started) return false;
    s.ledger.settle(Wait::No);  // what is ready: else a step late
    for (const Pool& p : s.pools)
        if (p.live() > 0) return false;
    return true;
}

// An extern's type as the program spells it: `float`, `vec3`, `bool`, `color`, `point`.
std::string languageName(const ir::Type& t) {
    if (t.isBool()) return "bool";
    return t.width == 1 ? "float" : "vec" + std::to_string(t.width);
}

std::string languageName(const ir::Extern& e) { return e.spelling.empty() ? languageName(e.type) : e.spelling; }
std::string languageName(const ir::Param& p) { return p.spelling.empty() ? languageName(p.type) : p.spelling; }

std::optional<std::string> System::reserve(size_t type, size_t rows) {
    detail::State& s = *state_;
    if (type >= s.pools.size()) return fmt::format("there is no object type {}", type);
    Pool& pool = s.pools[type];
    if (rows > pool.capacity())
        return fmt::format("{} holds at most {} objects (its @capacity, else the options' capacity), not {}",
                           pool.object().name, pool.capacity(), rows);
    pool.populate(rows);
    const detail::TypeInfo& info = s.types[type];
    if (!info.kills || rows == 0) return std::nullopt;
    // (Its kill lists: the update's chunks', taking turns with the ledger's — Ledger::fresh.)
    const size_t chunks = s.chunkCount(rows), per = s.backend.chunkRows();
    detail::TypeWork& work = s.work[type];
    if (work.killed.size() < chunks) work.killed.resize(chunks);
    for (size_t c = 0; c < chunks; ++c) work.killed[c].rows.reserve(std::min(per, rows - c * per));
    work.killTimes.reserve(rows);  // (a scaled step's: rt/system_speeds.cpp)
    s.ledger.reserve(type, chunks, per, 1);
    return std::nullopt;
}

std::optional<std::string> System::setExtern(std::string_view name, std::span<const float> value) {
    int index = externHandle(name);
    if (index < 0) return fmt::format("there is no extern `{}`", name);
    return setExtern(index, value);
}

std::optional<std::string> System::checkExtern(int index, std::span<const float> value, Value& out) {
    detail::State& s = *state_;
    if (index < 0 || static_cast<size_t>(index) >= s.module.externs.size())
        return fmt::format("there is no extern with handle {}", index);
    const ir::Extern& e = s.module.externs[static_cast<size_t>(index)];
    if (value.size() != static_cast<size_t>(e.type.width))
        return fmt::format("extern `{}` is a {}: it takes {} value{}, not {}", e.name, languageName(e), e.type.width,
                           e.type.width == 1 ? "" : "s", value.size());
    if (e.type.isBool() && value[0] != 0 && value[0] != 1)
        return fmt::format("extern `{}` is a bool: it takes true or false (or 1 or 0), not {}; it keeps its value", e.name,
                           value[0]);
    Value v;
    for (size_t i = 0; i < value.size(); ++i) v.f[i] = value[i];
    // One bad value from the host must not poison every particle that reads it: it is
    // refused and counted, and the extern keeps its last good value.
    if (!finite(v, e.type.width)) {
        ++s.stats.nonFiniteExterns;
        return fmt::format("extern `{}` takes finite values only; it keeps its value", e.name);
    }
    for (int c = 0; c < e.type.width; ++c) {
        auto i = static_cast<size_t>(c);
        bool below = e.low && v.f[i] < (*e.low)[i], above = e.high && v.f[i] > (*e.high)[i];
        if (below || above) {
            ++s.stats.outOfRangeExterns;
            return fmt::format("extern `{}`: {} is outside its range [{}, {}]; it keeps its value", e.name, v.f[i],
                               e.low ? (*e.low)[i] : -INFINITY, e.high ? (*e.high)[i] : INFINITY);
        }
    }
    out = v;
    return std::nullopt;
}

std::optional<std::string> System::setExtern(int index, std::span<const float> value) {
    detail::State& s = *state_;
    Value v;
    if (auto error = checkExtern(index, value, v)) return error;
    s.externs[static_cast<size_t>(index)] = v;
    // An instanced program reads its externs per instance: every instance takes this one.
    if (s.module.instanced())
        for (size_t slot = 0; slot < s.instances.size(); ++slot)
            s.instanceRecord(slot)[core::kInstanceOwnValues + static_cast<size_t>(index)] = v;
    ++s.externsVersion;
    // A render kernel may read it: what the step drew as it went is drawn again.
    for (detail::TypeWork& w : s.work) w.inStep.fresh = false;
    return std::nullopt;
}

std::optional<Value> System::externValue(std::string_view name) const {
    int index = externHandle(name);
    if (index < 0) return std::nullopt;
    return state_->externs[static_cast<size_t>(index)];
}

std::optional<std::string> System::checkCapacity(const ir::Module& module, const SystemOptions& options) {
    double memory = static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGE_SIZE));
    for (const ir::Object& o : module.objects) {
        uint64_t capacity = o.attributes.capacity ? *o.attributes.capacity : options.capacity;
        double bytes = static_cast<double>(capacity) * static_cast<double>(Pool::rowBytes(o));
        if (memory > 0 && bytes > memory)
            return fmt::format("object `{}`: a capacity of {} needs up to {:.1f} GB ({} bytes a row); this machine "
                               "has {:.1f} GB of memory", o.name, capacity, bytes / 1e9, Pool::rowBytes(o), memory / 1e9);
    }
    return std::nullopt;
}

std::optional<std::string> System::checkFiring(std::string_view name, size_t values) const {
    const ir::Trigger* trigger = nullptr;
    std::string names;
    for (const ir::Trigger& t : state_->module.triggers) {
        if (t.name == name) trigger = &t;
        names += (names.empty() ? "`" : ", `") + t.name + "`";
    }
    if (!trigger)
        return fmt::format("there is no trigger `{}`{}", name,
                           names.empty() ? " (the system has none)" : " (the triggers are " + names + ")");
    size_t width = 0;
    for (auto& p : trigger->hostParams()) width += static_cast<size_t>(p.type.width);
    if (values != width)
        return fmt::format("trigger `{}` takes {} number{}, not {}", name, width, width == 1 ? "" : "s", values);
    return std::nullopt;
}

std::optional<std::string> System::checkFiring(std::string_view name, std::span<const float> args) const {
    if (auto error = checkFiring(name, args.size())) return error;
    for (float a : args)
        if (!std::isfinite(a))
            return fmt::format("trigger `{}` takes finite numbers, not {}", name, a);
    return std::nullopt;
}

std::optional<std::string> System::fire(std::string_view name, std::span<const float> args) {
    if (auto error = checkFiring(name, args)) return error;
    detail::State& s = *state_;
    if (s.module.instanced() && s.instances[0].life == InstanceLife::Finished)  // the system's own, again
        s.setLife(0, InstanceLife::Playing);
    return fireOn(name, args, 0);
}

// A checked firing, on instance `slot` where the program is instanced.
std::optional<std::string> System::fireOn(std::string_view name, std::span<const float> args, uint32_t slot) {
    detail::State& s = *state_;
    const ir::Trigger* trigger = nullptr;
    for (const ir::Trigger& t : s.module.triggers)
        if (t.name == name) trigger = &t;
    std::vector<Value> params;
    size_t at = 0;
    for (auto& p : trigger->hostParams()) {
        Value v;
        for (int c = 0; c < p.type.width; ++c) v.f[static_cast<size_t>(c)] = args[at++];
        params.push_back(v);
    }
    if (s.module.instanced()) params.push_back(Value::scalar(static_cast<float>(slot)));
    start();
    s.ledger.settle(Wait::Yes);  // the rows the last step freed, before these objects take rows
    creation_->emitFromKernel(*trigger, params, kTriggerObject);
    creation_->drain(s.now);
    s.ledger.settle(Wait::No);
    drawing_->invalidate();
    return std::nullopt;
}

Bounds System::bounds(size_t type) {
    const DrawColumns& c = draw(type);
    if (c.rows == 0) return {};
    return state_->memory.bounds(c.visible, {c.position[0], c.position[1], c.position[2]},
                                 {c.constant[0], c.constant[1], c.constant[2]}, c.rows);
}

const DrawColumns& System::draw(size_t type) {
    start();
    return drawing_->draw(type);
}

std::vector<RenderPoint> System::points(size_t type) {
    start();
    return drawing_->points(type);
}

Stats System::stats() const {
    Stats out;
    stats(out);
    return out;
}

void System::stats(Stats& out) const {
    state_->ledger.settle(Wait::No);  // what is ready: else a step late
    drawing_->takeCounts();
    const detail::State& s = *state_;
    std::vector<TypeStats> types = std::move(out.types);
    out = s.stats;
    types = s.typeStats;  // (into the vector and names it had: no allocation when they fit)
    out.types = std::move(types);
    for (size_t t = 0; t < s.pools.size(); ++t) {
        out.types[t].live = s.pools[t].live();
        out.types[t].frozen = s.pools[t].frozen();
    }
}

}  // namespace psys::rt
