// The LLVM backend: IR kernels compiled to machine code with LLVM 19's ORC LLJIT.
//
// Each update and exports kernel becomes a loop over a range of a pool's rows, reading
// and writing the pool's columns in place (noalias pointers, one per column, so the loop
// vectorizes without run-time alias checks); every other kernel (init, spawn, render,
// uniform, trigger) becomes a function for one object, called as the interpreter is.
//
// Compiled code is cached by the kernel's text (and, for loops, its column layout): a
// system compiled again unchanged, or a second system with the same kernels, compiles
// nothing. See lane_emitter.h for the math modes; `Exact` gives the interpreter's
// results bit for bit.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "codegen_llvm/jit_options.h"
#include "rt/backend.h"

namespace psys::codegen_llvm {

struct CompileStats {
    size_t kernels = 0;      // functions compiled
    size_t cacheHits = 0;    // kernels found already compiled
    double seconds = 0;      // building LLVM IR, optimizing, generating machine code
};

class LlvmBackend : public rt::Backend {
public:
    explicit LlvmBackend(MathMode mode = MathMode::Fast);
    ~LlvmBackend() override;
    std::string name() const override { return "llvm"; }
    void run(const ir::Kernel& kernel, const rt::KernelInputs& in, std::vector<rt::Value>& yields) override;
    void runChildren(const ir::Kernel& spawn, const rt::KernelInputs& in, uint32_t firstChild, size_t count,
                     rt::Value* args, size_t stride) override;
    void prepare(const Plan& plan) override;
    void forget(const ir::Module& module) override;
    void runRows(const ir::Object& object, const ir::Kernel& kernel, const rt::BatchLayout& layout,
                 const rt::RowBatch& batch) override;
    bool concurrent() const override { return true; }

    CompileStats compileStats() const;
    // What the loop vectorizer said about every loop compiled so far.
    std::vector<VectorizeRemark> remarks() const;
    std::string cpu() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace psys::codegen_llvm
