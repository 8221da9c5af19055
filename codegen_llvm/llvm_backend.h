// The LLVM backend: IR kernels compiled to machine code with LLVM 19's ORC LLJIT.
//
// Every launch of rt/backend.h becomes compiled code: a kernel over a range of rows is a
// loop over the columns (noalias pointers, one per column, so the loop vectorizes without
// run-time alias checks), with the clock read from arguments or from per-row columns; a
// spawn kernel is a loop over the children of one emitter. The columns live in host
// memory (rt::HostMemory). `prepare` compiles every launch shape of a system at once, on
// every core.
//
// Compiled code is cached by a structural hash of the kernel (and the launch shape and
// column layout): a system compiled again unchanged, or a second system with the same
// kernels, compiles nothing. See lane_emitter.h for the math modes; `Exact` gives the
// interpreter's results bit for bit.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "codegen_llvm/jit_options.h"
#include "rt/backend.h"

namespace psys::codegen_llvm {

class LlvmBackend : public rt::Backend {
public:
    explicit LlvmBackend(MathMode mode = MathMode::Fast);
    ~LlvmBackend() override;
    std::string name() const override { return "llvm"; }
    rt::Memory& memory() override;
    void prepare(const rt::Plan& plan) override;
    void forget(const ir::Module& module) override;
    rt::RowsResult run(const rt::RowsLaunch& launch) override;
    void run(const rt::ChildrenLaunch& launch) override;
    // A neighbour group's terms as a loop over an object's candidates (pair_function.cpp),
    // compiled at the first fold.
    rt::PairFunction pairFunction(const ir::Object& object, const ir::Kernel& pair) override;
    bool concurrent() const override { return true; }
    bool marksDrawn() const override { return true; }  // render loops mark and count what they draw
    // Floats per vector register the loops over pools use (16 with AVX-512, 8 with AVX, else 4).
    unsigned lanes() const;
    rt::BackendReport report() const override;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace psys::codegen_llvm
