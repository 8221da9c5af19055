// LLVM's ORC LLJIT set up for psys kernels: the host CPU's features, the O3 pipeline
// (with glibc's vector math functions when fast maths is allowed), and the loop
// vectorizer's remarks kept, so a tool or a test can say whether a loop vectorized.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <llvm/IR/LLVMContext.h>
#include <llvm/IR/Module.h>

#include "codegen_llvm/lane_emitter.h"

namespace psys::codegen_llvm {

class JitEngine {
public:
    explicit JitEngine(MathMode mode);
    ~JitEngine();

    // A context and an empty module with the JIT's target and data layout.
    std::unique_ptr<llvm::LLVMContext> newContext() const;
    std::unique_ptr<llvm::Module> newModule(llvm::LLVMContext& context) const;

    // Verifies and optimizes `module`, hands it to the JIT and returns the address of
    // each of `names`. Throws std::runtime_error when LLVM refuses it.
    std::vector<void*> add(std::unique_ptr<llvm::LLVMContext> context, std::unique_ptr<llvm::Module> module,
                           const std::vector<std::string>& names);

    const std::vector<VectorizeRemark>& remarks() const { return remarks_; }
    std::string cpu() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    std::vector<VectorizeRemark> remarks_;
};

}  // namespace psys::codegen_llvm
