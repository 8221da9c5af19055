// A system compiled ahead of time (`psysc build`): its kernels' machine code linked into
// the host, found by the key of each launch shape (native::Request) in the table the build
// wrote beside it. No compiler runs: a launch shape the table lacks is an error.
#pragma once

#include <span>
#include <string>

#include "native/compiled_backend.h"

namespace psys::native {

// One row of an AOT build's table (psys_aot_kernel in include/psys/psys.h).
struct AotKernel {
    uint64_t keyLow, keyHigh;
    void* code;
};

class AotBackend final : public CompiledBackend {
public:
    // `target`: the CPU the code was compiled for (for reports).
    AotBackend(bool exact, std::span<const AotKernel> table, std::string target);
    std::string name() const override { return "aot"; }
    rt::BackendReport report() const override;

protected:
    void provide(const std::vector<Request>& requests) override;

private:
    std::span<const AotKernel> table_;
    std::string target_;
};

}  // namespace psys::native
