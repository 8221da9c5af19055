// The LLVM backend: IR kernels compiled to machine code with LLVM 19's ORC LLJIT.
//
// This first version keeps the run-time's per-object calling convention (one call per
// object per kernel, like the interpreter) so that it can be checked against the
// interpreter bit for bit; the loops over whole pools come with the batched interface.
// Every operation is compiled to give exactly the interpreter's float result: no
// fast-math flags, no contraction into fused multiply-adds, the same libm functions.
#pragma once

#include <memory>
#include <string>

#include "rt/backend.h"

namespace psys::codegen_llvm {

class LlvmBackend : public rt::Backend {
public:
    LlvmBackend();
    ~LlvmBackend() override;
    std::string name() const override { return "llvm"; }
    void run(const ir::Kernel& kernel, const rt::KernelInputs& in, std::vector<rt::Value>& yields) override;

    // Kernels compiled so far, and the time spent compiling them.
    size_t compiledKernels() const;
    double compileSeconds() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace psys::codegen_llvm
