#include "native/aot_backend.h"

#include <stdexcept>

namespace psys::native {

AotBackend::AotBackend(bool exact, std::span<const AotKernel> table, std::string target)
    : CompiledBackend(exact), table_(table), target_(std::move(target)) {}

rt::BackendReport AotBackend::report() const {
    rt::BackendReport r;
    r.kernels = table_.size();
    r.target = target_;
    return r;
}

void AotBackend::provide(const std::vector<Request>& requests) {
    for (const Request& r : requests) {
        const AotKernel* found = nullptr;
        for (const AotKernel& k : table_)
            if (k.keyLow == r.key.low && k.keyHigh == r.key.high) found = &k;
        if (!found)
            throw std::runtime_error("the ahead-of-time build has no code for a kernel of `" + r.object->name +
                                     "` (" + std::string(ir::kernelName(r.shape.kernel->kind)) +
                                     "): build it again with this version of psysc");
        record(r.shape, found->code);
    }
}

}  // namespace psys::native
