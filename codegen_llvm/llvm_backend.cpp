#include "codegen_llvm/llvm_backend.h"

#include <chrono>
#include <map>
#include <mutex>
#include <stdexcept>
#include <unordered_map>

#include "codegen_llvm/jit_engine.h"
#include "codegen_llvm/kernel_functions.h"
#include "interp/interpreter.h"
#include "ir/printer.h"

namespace psys::codegen_llvm {

using namespace ir;

namespace {

const char* modeName(MathMode mode) { return mode == MathMode::Exact ? "exact" : "fast"; }

}  // namespace

struct LlvmBackend::Impl {
    MathMode mode;
    JitEngine engine;
    std::mutex mutex;  // runRows may be called from several threads
    std::unordered_map<std::string, void*> byText;     // compiled code by kernel text
    // A function for one object or for children, with the parent reads its caller gathers.
    template <typename Fn>
    struct Entry {
        Fn fn;
        std::vector<const Inst*> parentReads;  // in instruction order
    };
    std::unordered_map<const Kernel*, Entry<ObjectFn>> objectFns;  // the kernels of prepared modules
    std::map<std::pair<const Kernel*, rt::RowsMode>, RowsFn> rowsFns;
    std::unordered_map<const Kernel*, Entry<ChildrenFn>> childrenFns;
    CompileStats stats;
    int counter = 0;
    std::vector<rt::Value> parents;
    interp::Interpreter interpreter;

    unsigned lanes;

    explicit Impl(MathMode m) : mode(m), engine(m), lanes(engine.floatLanes()) {}

    enum class Shape { Object, Children, Rows };
    struct Request {
        const Object* object;  // Rows only
        const Kernel* kernel;
        std::string key;
        Shape shape;
        rt::RowsMode rowsMode = rt::RowsMode::Step;
    };

    // Compiles what is not compiled yet (one module per function, compiled concurrently)
    // and fills the maps.
    void compile(const std::vector<Request>& requests) {
        auto start = std::chrono::steady_clock::now();
        std::vector<JitEngine::Unit> units;
        std::vector<const Request*> built;
        std::unordered_map<std::string, size_t> inThisBatch;
        for (const Request& r : requests) {
            if (byText.count(r.key) || inThisBatch.count(r.key)) {
                ++stats.cacheHits;
                continue;
            }
            // Names say what a function is, for remarks and profiles: drop.update.7
            std::string name = (r.object ? r.object->name + "." : std::string()) + kernelName(r.kernel->kind);
            if (r.rowsMode == rt::RowsMode::FirstUpdate) name += ".first";
            if (r.shape == Shape::Object) name += ".object";
            if (r.shape == Shape::Children) name += ".children";
            name += "." + std::to_string(counter++);
            JitEngine::Unit unit{engine.newContext(), nullptr, name};
            unit.module = engine.newModule(*unit.context);
            switch (r.shape) {
                case Shape::Rows: buildRowsFunction(*unit.module, mode, lanes, *r.object, *r.kernel, r.rowsMode, name); break;
                case Shape::Object: buildObjectFunction(*unit.module, mode, *r.kernel, name); break;
                case Shape::Children: buildChildrenFunction(*unit.module, mode, *r.kernel, name); break;
            }
            inThisBatch[r.key] = units.size();
            units.push_back(std::move(unit));
            built.push_back(&r);
        }
        if (!units.empty()) {
            size_t count = units.size();
            auto addresses = engine.add(std::move(units));
            for (size_t n = 0; n < count; ++n) byText[built[n]->key] = addresses[n];
            stats.kernels += count;
        }
        for (const Request& r : requests) {
            void* code = byText.at(r.key);
            switch (r.shape) {
                case Shape::Rows: rowsFns[{r.kernel, r.rowsMode}] = reinterpret_cast<RowsFn>(code); break;
                case Shape::Object: objectFns[r.kernel] = {reinterpret_cast<ObjectFn>(code), parentReads(*r.kernel)}; break;
                case Shape::Children:
                    childrenFns[r.kernel] = {reinterpret_cast<ChildrenFn>(code), parentReads(*r.kernel)};
                    break;
            }
        }
        stats.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }

    // Kernels that run once per step or per trigger: the interpreter runs them in less
    // time than compiling them would take.
    static bool interpreted(const Kernel& k) {
        switch (k.kind) {
            case KernelKind::Start: case KernelKind::Trigger: case KernelKind::UniformUpdate:
            case KernelKind::UniformRender: case KernelKind::UniformExports:
                return true;
            default:
                return false;
        }
    }

    // The values of a kernel's parent reads for one object, in instruction order.
    const std::vector<rt::Value>& gatherParents(const std::vector<const Inst*>& reads, const rt::KernelInputs& in) {
        parents.clear();
        for (const Inst* i : reads) {
            if (i->op == Op::ParentExport) parents.push_back(in.parentExport(i->attr2, i->attr));
            else if (i->op == Op::ParentAlive) parents.push_back(rt::Value::boolean(in.parentAlive(i->attr2)));
            else parents.push_back(rt::Value::scalar(in.parentAge(i->attr2)));
        }
        return parents;
    }

    static std::vector<const Inst*> parentReads(const Kernel& k) {
        std::vector<const Inst*> reads;
        for (const Inst& i : k.insts())
            if (i.op == Op::ParentExport || i.op == Op::ParentAlive || i.op == Op::ParentAge) reads.push_back(&i);
        return reads;
    }

    Request objectRequest(const Kernel& k) {
        return {nullptr, &k, std::string("object ") + modeName(mode) + "\n" + print(k), Shape::Object};
    }
    Request childrenRequest(const Kernel& k) {
        return {nullptr, &k, std::string("children ") + modeName(mode) + "\n" + print(k), Shape::Children};
    }
    Request rowsRequest(const Object& o, const Kernel& k, rt::RowsMode rowsMode) {
        std::string key = std::string("rows ") + modeName(mode) + " " + std::to_string(static_cast<int>(rowsMode)) + " " +
                          rt::batchLayout(o, k).signature() + "\n" + print(k);
        if (rowsMode == rt::RowsMode::FirstUpdate)
            if (auto served = uniformFor(k.kind))
                if (const Kernel* u = o.kernel(*served)) key += "uniform\n" + print(*u);
        return {&o, &k, std::move(key), Shape::Rows, rowsMode};
    }
};

LlvmBackend::LlvmBackend(MathMode mode) : impl_(std::make_unique<Impl>(mode)) {}
LlvmBackend::~LlvmBackend() = default;

CompileStats LlvmBackend::compileStats() const { return impl_->stats; }
std::vector<VectorizeRemark> LlvmBackend::remarks() const { return impl_->engine.remarks(); }
std::string LlvmBackend::cpu() const { return impl_->engine.cpu(); }

void LlvmBackend::prepare(const Plan& plan) {
    std::lock_guard lock(impl_->mutex);
    std::vector<Impl::Request> requests;
    for (const Kernel* k : plan.objectKernels) {
        if (Impl::interpreted(*k)) continue;
        // The run-time asks for spawn kernels' arguments a batch of children at a time.
        requests.push_back(k->kind == KernelKind::Spawn ? impl_->childrenRequest(*k) : impl_->objectRequest(*k));
    }
    for (const Plan::Loop& l : plan.loops) requests.push_back(impl_->rowsRequest(*l.object, *l.kernel, l.mode));
    impl_->compile(requests);
}

// Compiled code stays (it is cached by text); only the addresses are dropped.
void LlvmBackend::forget(const Module& module) {
    std::lock_guard lock(impl_->mutex);
    auto drop = [this](const Kernel& k) {
        impl_->objectFns.erase(&k);
        impl_->childrenFns.erase(&k);
        for (auto mode : {rt::RowsMode::Step, rt::RowsMode::Init, rt::RowsMode::FirstUpdate}) impl_->rowsFns.erase({&k, mode});
    };
    drop(module.start.kernel);
    for (const Trigger& t : module.triggers) drop(t.kernel);
    for (const Object& o : module.objects)
        for (const Kernel& k : o.kernels) drop(k);
}

void LlvmBackend::run(const Kernel& kernel, const rt::KernelInputs& in, std::vector<rt::Value>& yields) {
    auto it = impl_->objectFns.find(&kernel);
    if (it == impl_->objectFns.end() && Impl::interpreted(kernel)) {
        impl_->interpreter.run(kernel, in, yields);
        return;
    }
    if (it == impl_->objectFns.end()) {
        std::lock_guard lock(impl_->mutex);
        impl_->compile({impl_->objectRequest(kernel)});
        it = impl_->objectFns.find(&kernel);
    }
    const auto& parents = impl_->gatherParents(it->second.parentReads, in);
    float scalars[4] = {in.age, in.dt, in.time, in.first ? 1.0f : 0.0f};
    uint32_t keys[4] = {in.seed, in.objectId, in.draw, in.childDraw};
    yields.resize(kernel.yields.size());
    it->second.fn(in.params, in.state, in.externs, in.uniforms, parents.data(), scalars, keys, yields.data());
}

void LlvmBackend::runChildren(const Kernel& spawn, const rt::KernelInputs& in, uint32_t firstChild, size_t count,
                              rt::Value* args, size_t stride) {
    auto it = impl_->childrenFns.find(&spawn);
    if (it == impl_->childrenFns.end()) {
        std::lock_guard lock(impl_->mutex);
        impl_->compile({impl_->childrenRequest(spawn)});
        it = impl_->childrenFns.find(&spawn);
    }
    const auto& parents = impl_->gatherParents(it->second.parentReads, in);
    float scalars[4] = {in.age, in.dt, in.time, in.first ? 1.0f : 0.0f};
    uint32_t keys[4] = {in.seed, in.objectId, in.draw, firstChild};
    it->second.fn(in.params, in.state, in.externs, in.uniforms, parents.data(), scalars, keys, args,
                  static_cast<int64_t>(count), static_cast<int64_t>(stride));
}

void LlvmBackend::runRows(const Object& object, const Kernel& kernel, const rt::BatchLayout&, const rt::RowBatch& batch) {
    RowsFn fn;
    {
        std::lock_guard lock(impl_->mutex);
        auto it = impl_->rowsFns.find({&kernel, batch.mode});
        if (it == impl_->rowsFns.end()) {
            impl_->compile({impl_->rowsRequest(object, kernel, batch.mode)});
            it = impl_->rowsFns.find({&kernel, batch.mode});
        }
        fn = it->second;
    }
    fn(batch.columns, batch.mask, static_cast<int64_t>(batch.begin), static_cast<int64_t>(batch.end), batch.externs,
       batch.uniforms, batch.time, batch.dt, batch.seed, batch.draw);
}

}  // namespace psys::codegen_llvm