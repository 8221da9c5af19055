#include "codegen_llvm/llvm_backend.h"

#include <chrono>
#include <map>
#include <mutex>
#include <stdexcept>
#include <unordered_map>

#include "codegen_llvm/jit_engine.h"
#include "codegen_llvm/kernel_functions.h"
#include "ir/hash.h"

namespace psys::codegen_llvm {

using namespace ir;
using rt::Clock;

namespace {

// A compiled launch of one kernel: its rows shape (clock sources) or children.
struct Shape {
    const Kernel* kernel;
    bool children;
    Clock::Source now, dt;
    bool operator<(const Shape& o) const {
        return std::tie(kernel, children, now, dt) < std::tie(o.kernel, o.children, o.now, o.dt);
    }
};

}  // namespace

struct LlvmBackend::Impl {
    MathMode mode;
    JitEngine engine;
    rt::HostMemory memory;
    std::mutex mutex;  // launches may come from several threads
    std::unordered_map<Hash128, void*, Hash128Hasher> byHash;  // compiled code by what it computes
    std::map<Shape, void*> functions;                        // the kernels of prepared modules
    rt::BackendReport stats;
    int counter = 0;
    unsigned lanes;

    explicit Impl(MathMode m) : mode(m), engine(m), lanes(engine.floatLanes()) {}

    struct Request {
        const Object* object;
        Shape shape;
        const Kernel* uniformKernel;  // rows with a per-row clock: evaluated per row
        bool vectorize;
        Hash128 key;
    };

    Request request(const Object& o, const Kernel& k, bool children, Clock::Source now, Clock::Source dt,
                    bool many = true) {
        const Kernel* uniform = nullptr;
        if (!children && Clock::perRow(now, dt))
            if (auto served = uniformFor(k.kind)) uniform = o.kernel(*served);
        Hasher h;
        h.add(mode == MathMode::Exact).add(children).add(static_cast<uint64_t>(now)).add(static_cast<uint64_t>(dt));
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

    // Compiles what is not compiled yet (one module per function, compiled concurrently)
    // and maps the launch shapes to their code. The lock is held only around the maps, so
    // a system keeps running on this backend while another's kernels compile (a viewer
    // reloading a file).
    void compile(const std::vector<Request>& requests) {
        auto start = std::chrono::steady_clock::now();
        std::vector<std::pair<const Request*, std::string>> missing;  // with the function's name
        {
            std::lock_guard lock(mutex);
            std::unordered_map<Hash128, bool, Hash128Hasher> inThisBatch;
            for (const Request& r : requests) {
                if (byHash.count(r.key) || inThisBatch.count(r.key)) {
                    ++stats.cacheHits;
                    continue;
                }
                inThisBatch[r.key] = true;
                // Names say what a function is, for remarks and profiles: drop.update.created.7
                std::string name = r.object->name + "." + kernelName(r.shape.kernel->kind);
                if (r.shape.children) name += ".children";
                else if (Clock::perRow(r.shape.now, r.shape.dt)) name += ".created";
                missing.push_back({&r, name + "." + std::to_string(counter++)});
            }
        }
        std::vector<JitEngine::Unit> units;
        for (auto& [r, name] : missing) {
            JitEngine::Unit unit{engine.newContext(), nullptr, name};
            unit.module = engine.newModule(*unit.context);
            if (r->shape.kernel->kind == KernelKind::Pair)
                buildPairFunction(*unit.module, mode, *r->object, *r->shape.kernel, name);
            else if (r->shape.children)
                buildChildrenFunction(*unit.module, mode, *r->object, *r->shape.kernel, name);
            else
                buildRowsFunction(*unit.module, mode, r->vectorize ? lanes : 0, *r->object, *r->shape.kernel,
                                  r->uniformKernel, r->shape.now, r->shape.dt, name);
            units.push_back(std::move(unit));
        }
        std::vector<void*> addresses;
        if (!units.empty()) addresses = engine.add(std::move(units));
        std::lock_guard lock(mutex);
        for (size_t n = 0; n < missing.size(); ++n) byHash[missing[n].first->key] = addresses[n];
        stats.kernels += missing.size();
        for (const Request& r : requests) functions[r.shape] = byHash.at(r.key);
        stats.compileSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }

    // The compiled function for a launch shape (compiled now if `prepare` did not list it).
    void* function(const Object& o, const Kernel& k, bool children, Clock::Source now, Clock::Source dt) {
        Shape shape{&k, children, now, dt};
        {
            std::lock_guard lock(mutex);
            auto it = functions.find(shape);
            if (it != functions.end()) return it->second;
        }
        compile({request(o, k, children, now, dt)});
        std::lock_guard lock(mutex);
        return functions.at(shape);
    }

    // The host addresses of a launch's columns.
    std::vector<void*> addresses(std::span<const rt::Buffer> columns) {
        std::vector<void*> out(columns.size(), nullptr);
        for (size_t i = 0; i < columns.size(); ++i)
            if (columns[i].valid()) out[i] = memory.host(columns[i]);
        return out;
    }
};

LlvmBackend::LlvmBackend(MathMode mode) : impl_(std::make_unique<Impl>(mode)) {}
LlvmBackend::~LlvmBackend() = default;

rt::Memory& LlvmBackend::memory() { return impl_->memory; }
unsigned LlvmBackend::lanes() const { return impl_->lanes; }

rt::BackendReport LlvmBackend::report() const {
    std::lock_guard lock(impl_->mutex);
    rt::BackendReport r = impl_->stats;
    r.target = impl_->engine.cpu();
    r.remarks = impl_->engine.remarks();
    r.calls = impl_->engine.calls();
    r.fromDisk = impl_->engine.fromDisk();
    return r;
}

void LlvmBackend::prepare(const rt::Plan& plan) {
    std::vector<Impl::Request> requests;
    for (const rt::Plan::Rows& r : plan.rows)
        requests.push_back(impl_->request(*r.object, *r.kernel, false, r.now, r.dt, r.many));
    for (const rt::Plan::Children& c : plan.children)
        requests.push_back(impl_->request(*c.object, *c.spawn, true, Clock::Source::Uniform, Clock::Source::Uniform));
    impl_->compile(requests);
}

// Compiled code stays (it is cached by hash); only the kernels' addresses are dropped.
void LlvmBackend::forget(const Module& module) {
    std::lock_guard lock(impl_->mutex);
    for (const Object& o : module.objects)
        for (const Kernel& k : o.kernels)
            for (auto it = impl_->functions.begin(); it != impl_->functions.end();)
                it = it->first.kernel == &k ? impl_->functions.erase(it) : std::next(it);
}

rt::RowsResult LlvmBackend::run(const rt::RowsLaunch& l) {
    auto fn = reinterpret_cast<RowsFn>(impl_->function(*l.object, *l.kernel, false, l.clock.now, l.clock.dt));
    std::vector<void*> columns = impl_->addresses(l.columns);
    const auto* mask = static_cast<const uint8_t*>(impl_->memory.host(l.mask));
    RowCounts counts = fn(columns.data(), mask, static_cast<int64_t>(l.begin), static_cast<int64_t>(l.end), l.externs,
                          l.uniforms, l.clock.nowValue, l.clock.dtValue, l.clock.first ? 1u : 0u, l.seed, l.draw);
    if (l.kernel->kind == ir::KernelKind::Render) {  // a render loop counts what it drew instead (marksDrawn)
        rt::RowsResult drawn;
        drawn.drawn = static_cast<size_t>(counts.killed);
        drawn.nonFinite = static_cast<size_t>(counts.unstable);
        return drawn;
    }
    return {static_cast<size_t>(counts.killed), static_cast<size_t>(counts.unstable)};
}

rt::PairFunction LlvmBackend::pairFunction(const Object& object, const Kernel& pair) {
    return reinterpret_cast<rt::PairFunction>(
        impl_->function(object, pair, false, Clock::Source::Uniform, Clock::Source::Uniform));
}

void LlvmBackend::run(const rt::ChildrenLaunch& l) {
    auto fn = reinterpret_cast<ChildrenFn>(
        impl_->function(*l.object, *l.spawn, true, Clock::Source::Uniform, Clock::Source::Uniform));
    std::vector<void*> columns = impl_->addresses(l.columns);
    std::vector<void*> args = impl_->addresses(l.args);
    fn(columns.data(), static_cast<int64_t>(l.row), l.parents, l.externs, l.clock.nowValue, l.clock.dtValue,
       l.clock.first ? 1u : 0u, l.seed, l.draw, l.firstChild, static_cast<int64_t>(l.count),
       reinterpret_cast<float* const*>(args.data()), static_cast<int64_t>(l.argsFirst));
}

}  // namespace psys::codegen_llvm
