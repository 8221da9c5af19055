#include "codegen_llvm/llvm_backend.h"

#include <chrono>
#include <mutex>
#include <unordered_map>

#include "codegen_llvm/jit_engine.h"
#include "codegen_llvm/kernel_functions.h"
#include "ir/hash.h"

namespace psys::codegen_llvm {

using namespace ir;
using native::Request;
using rt::Clock;

struct LlvmBackend::Impl {
    MathMode mode;
    JitEngine engine;
    std::mutex mutex;  // the maps below: kernels compile while other systems run
    std::unordered_map<Hash128, void*, Hash128Hasher> byHash;  // compiled code by what it computes
    rt::BackendReport stats;
    int counter = 0;
    unsigned lanes;

    Impl(MathMode m, std::optional<std::string> cache) : mode(m), engine(m, std::move(cache)), lanes(engine.floatLanes()) {}
};

LlvmBackend::LlvmBackend(MathMode mode, std::optional<std::string> cache)
    : native::CompiledBackend(mode == MathMode::Exact), impl_(std::make_unique<Impl>(mode, std::move(cache))) {}
LlvmBackend::~LlvmBackend() = default;

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

// The lock is held only around the maps, so a system keeps running on this backend while
// another's kernels compile (a viewer reloading a file).
void LlvmBackend::provide(const std::vector<Request>& requests) {
    Impl& m = *impl_;
    auto start = std::chrono::steady_clock::now();
    std::vector<std::pair<const Request*, std::string>> missing;  // with the function's name
    {
        std::lock_guard lock(m.mutex);
        std::unordered_map<Hash128, bool, Hash128Hasher> inThisBatch;
        for (const Request& r : requests) {
            if (m.byHash.count(r.key) || inThisBatch.count(r.key)) {
                ++m.stats.cacheHits;
                continue;
            }
            inThisBatch[r.key] = true;
            missing.push_back({&r, functionName(r, m.counter++)});
        }
    }
    std::vector<JitEngine::Unit> units;
    for (auto& [r, name] : missing) {
        JitEngine::Unit unit{m.engine.newContext(), nullptr, name};
        unit.module = m.engine.newModule(*unit.context);
        buildFunction(*unit.module, m.mode, m.lanes, *r, name);
        units.push_back(std::move(unit));
    }
    std::vector<void*> addresses;
    if (!units.empty()) addresses = m.engine.add(std::move(units));
    std::vector<std::pair<native::Shape, void*>> found;
    {
        std::lock_guard lock(m.mutex);
        for (size_t n = 0; n < missing.size(); ++n) m.byHash[missing[n].first->key] = addresses[n];
        m.stats.kernels += missing.size();
        for (const Request& r : requests) found.push_back({r.shape, m.byHash.at(r.key)});
        m.stats.compileSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    for (auto& [shape, code] : found) record(shape, code);
}

}  // namespace psys::codegen_llvm
