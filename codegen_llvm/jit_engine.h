// LLVM's ORC LLJIT set up for psys kernels: the host CPU's features, the O3 pipeline
// (with glibc's vector math functions when fast maths is allowed), every core compiling
// (one module per kernel, optimized and compiled concurrently), and the loop
// vectorizer's remarks kept, so a tool or a test can say whether a loop vectorized.
#pragma once

#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <llvm/IR/LLVMContext.h>
#include <llvm/IR/Module.h>

#include "codegen_llvm/lane_emitter.h"
#include "rt/backend.h"

namespace psys::codegen_llvm {

class JitEngine {
public:
    // cache: the folder of compiled objects ("": none); unset: PSYS_JIT_CACHE, else
    // $XDG_CACHE_HOME/psys/jit or ~/.cache/psys/jit (ObjectCache).
    explicit JitEngine(MathMode mode, std::optional<std::string> cache = std::nullopt);
    ~JitEngine();

    // A context and an empty module with the JIT's target and data layout.
    std::unique_ptr<llvm::LLVMContext> newContext() const;
    std::unique_ptr<llvm::Module> newModule(llvm::LLVMContext& context) const;

    // One module that defines the function `name`.
    struct Unit {
        std::unique_ptr<llvm::LLVMContext> context;
        std::unique_ptr<llvm::Module> module;
        std::string name;
    };
    // Verifies the units, optimizes and compiles them (concurrently) and returns the
    // address of each one's function. Throws std::runtime_error when LLVM refuses one.
    std::vector<void*> add(std::vector<Unit> units);

    // What the loop vectorizer said about every loop compiled so far.
    std::vector<rt::BackendReport::Remark> remarks() const;
    // Modules whose machine code came from the disk cache (see ObjectCache in the .cpp).
    size_t fromDisk() const;
    // The functions from outside the JIT (libm, libmvec, libc) that code linked so far calls.
    std::vector<std::string> calls() const;
    std::string cpu() const;
    unsigned floatLanes() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace psys::codegen_llvm
