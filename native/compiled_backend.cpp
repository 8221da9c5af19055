#include "native/compiled_backend.h"

#include <array>
#include <span>
#include <vector>

#include "core/few.h"
#include "rt/system.h"

namespace psys::native {

using namespace ir;
using rt::Clock;

Request request(bool exact, const Object& o, const Kernel& k, bool children, Clock::Source now, Clock::Source dt,
                bool many) {
    const Kernel* uniform = nullptr;
    if (!children && Clock::perRow(now, dt))
        if (auto served = uniformFor(k.kind)) uniform = o.kernel(*served);
    Hasher h;
    h.add(exact).add(children).add(static_cast<uint64_t>(now)).add(static_cast<uint64_t>(dt));
    h.add(many).add(structuralHash(k));
    if (k.kind == KernelKind::Pair) {  // its folds: how each combines, where its components go
        for (const Fold& f : o.folds)
            h.add(static_cast<uint64_t>(f.group == k.site)).add(static_cast<uint64_t>(f.reduce)).add(static_cast<uint64_t>(f.type.width));
    } else {
        h.add(rt::columnLayout(o, k).signature());
    }
    if (uniform) h.add(structuralHash(*uniform));
    return {&o, {&k, children, now, dt}, uniform, many, h.finish()};
}

std::vector<Request> requests(bool exact, const Module& module) {
    std::vector<Request> out;
    rt::Plan plan = rt::launchPlan(module);
    for (const rt::Plan::Rows& r : plan.rows) out.push_back(request(exact, *r.object, *r.kernel, false, r.now, r.dt, r.many));
    for (const rt::Plan::Children& c : plan.children)
        out.push_back(request(exact, *c.object, *c.spawn, true, Clock::Source::Uniform, Clock::Source::Uniform));
    for (const Object& o : module.objects)
        for (const Kernel& k : o.kernels)
            if (k.kind == KernelKind::Pair)
                out.push_back(request(exact, o, k, false, Clock::Source::Uniform, Clock::Source::Uniform));
    return out;
}

void CompiledBackend::prepare(const rt::Plan& plan) {
    std::vector<Request> requests;
    for (const rt::Plan::Rows& r : plan.rows)
        requests.push_back(request(exact_, *r.object, *r.kernel, false, r.now, r.dt, r.many));
    for (const rt::Plan::Children& c : plan.children)
        requests.push_back(request(exact_, *c.object, *c.spawn, true, Clock::Source::Uniform, Clock::Source::Uniform));
    provide(requests);
}

void CompiledBackend::record(const Shape& shape, void* code) {
    std::lock_guard lock(mutex_);
    functions_[shape] = code;
}

// Compiled code stays with its provider; only the kernels' addresses are dropped.
void CompiledBackend::forget(const Module& module) {
    std::lock_guard lock(mutex_);
    for (const Object& o : module.objects)
        for (const Kernel& k : o.kernels)
            for (auto it = functions_.begin(); it != functions_.end();)
                it = it->first.kernel == &k ? functions_.erase(it) : std::next(it);
}

void* CompiledBackend::function(const Object& o, const Kernel& k, bool children, Clock::Source now, Clock::Source dt) {
    Shape shape{&k, children, now, dt};
    {
        std::lock_guard lock(mutex_);
        auto it = functions_.find(shape);
        if (it != functions_.end()) return it->second;
    }
    provide({request(exact_, o, k, children, now, dt)});
    std::lock_guard lock(mutex_);
    return functions_.at(shape);
}

namespace {
// The host addresses of a launch's columns (null for an invalid buffer), on the stack up
// to 96 (core/few.h: a launch allocates nothing on whatever thread runs it).
class Addresses {
public:
    Addresses(rt::HostMemory& memory, std::span<const rt::Buffer> columns) : data_(columns.size()) {
        for (size_t i = 0; i < columns.size(); ++i) data_[i] = columns[i].valid() ? memory.host(columns[i]) : nullptr;
    }
    void** data() { return data_.data(); }

private:
    core::Few<void*, 96> data_;
};
}  // namespace

rt::RowsResult CompiledBackend::run(const rt::RowsLaunch& l) {
    auto fn = reinterpret_cast<RowsFn>(function(*l.object, *l.kernel, false, l.clock.now, l.clock.dt));
    Addresses columns(memory_, l.columns);
    const auto* mask = static_cast<const uint8_t*>(memory_.host(l.mask));
    RowCounts counts = fn(columns.data(), mask, static_cast<int64_t>(l.begin), static_cast<int64_t>(l.end), l.externs,
                          l.uniforms, l.clock.nowValue, l.clock.dtValue, l.clock.first ? 1u : 0u, l.seed, l.draw);
    if (l.kernel->kind == KernelKind::Render) {  // a render loop counts what it drew instead (marksDrawn)
        rt::RowsResult drawn;
        drawn.drawn = static_cast<size_t>(counts.killed);
        drawn.nonFinite = static_cast<size_t>(counts.unstable);
        return drawn;
    }
    return {static_cast<size_t>(counts.killed), static_cast<size_t>(counts.unstable)};
}

rt::PairFunction CompiledBackend::pairFunction(const Object& object, const Kernel& pair) {
    return reinterpret_cast<rt::PairFunction>(function(object, pair, false, Clock::Source::Uniform, Clock::Source::Uniform));
}

void CompiledBackend::run(const rt::ChildrenLaunch& l) { runChildren({&l, 1}); }

namespace {
// Whether two launches run one kernel on the same columns: an emit site's emitters'.
bool sameSite(const rt::ChildrenLaunch& a, const rt::ChildrenLaunch& b) {
    return a.spawn == b.spawn && a.object == b.object && a.columns.data() == b.columns.data() &&
           a.columns.size() == b.columns.size() && a.args.data() == b.args.data() && a.args.size() == b.args.size();
}
}  // namespace

// A step's launches come an emitter at a time, and an effect played many times has many
// emitters of one site in a row (docs/embedding.md, "Instances"): such a run of launches
// finds its code and its columns' addresses once.
void CompiledBackend::runChildren(std::span<const rt::ChildrenLaunch> launches) {
    for (size_t i = 0; i < launches.size();) {
        const rt::ChildrenLaunch& first = launches[i];
        if (first.records.valid()) {  // one launch an emitter, read from the records
            rt::Backend::runChildren(launches.subspan(i, 1));
            ++i;
            continue;
        }
        size_t end = i + 1;
        while (end < launches.size() && !launches[end].records.valid() && sameSite(first, launches[end])) ++end;
        auto fn = reinterpret_cast<ChildrenFn>(
            function(*first.object, *first.spawn, true, Clock::Source::Uniform, Clock::Source::Uniform));
        Addresses columns(memory_, first.columns), args(memory_, first.args);
        for (; i < end; ++i) {
            const rt::ChildrenLaunch& l = launches[i];
            fn(columns.data(), static_cast<int64_t>(l.row), l.parents, l.externs, l.clock.nowValue, l.clock.dtValue,
               l.clock.first ? 1u : 0u, l.seed, l.draw, l.firstChild, static_cast<int64_t>(l.count),
               reinterpret_cast<float* const*>(args.data()), static_cast<int64_t>(l.argsFirst));
        }
    }
}

}  // namespace psys::native
