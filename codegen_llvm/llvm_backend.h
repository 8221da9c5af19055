// The LLVM backend: IR kernels compiled to machine code with LLVM 19's ORC LLJIT.
//
// Every launch of rt/backend.h becomes compiled code: a kernel over a range of rows is a
// loop over the columns (noalias pointers, one per column, so the loop vectorizes without
// run-time alias checks), with the clock read from arguments or from per-row columns; a
// spawn kernel is a loop over the children of one emitter. The columns live in host
// memory (rt::HostMemory). `prepare` compiles every launch shape of a system at once, on
// every core; the calls are native::CompiledBackend's, which AOT-compiled systems share.
//
// Compiled code is cached by a structural hash of the kernel (and the launch shape and
// column layout): a system compiled again unchanged, or a second system with the same
// kernels, compiles nothing. See lane_emitter.h for the math modes; `Exact` gives the
// interpreter's results bit for bit.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "codegen_llvm/jit_options.h"
#include "native/compiled_backend.h"

namespace psys::codegen_llvm {

class LlvmBackend : public native::CompiledBackend {
public:
    // cache: the folder of compiled objects ("": none; unset: JitEngine's default).
    explicit LlvmBackend(MathMode mode = MathMode::Fast, std::optional<std::string> cache = std::nullopt);
    ~LlvmBackend() override;
    std::string name() const override { return "llvm"; }
    // Floats per vector register the loops over pools use (16 with AVX-512, 8 with AVX, else 4).
    unsigned lanes() const;
    rt::BackendReport report() const override;

protected:
    // Compiles what is not compiled yet (one module per function, compiled concurrently).
    void provide(const std::vector<native::Request>& requests) override;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace psys::codegen_llvm
