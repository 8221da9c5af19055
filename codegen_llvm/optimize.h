// The optimization every compiled kernel goes through, the JIT's (jit_engine.cpp) and an
// ahead-of-time build's (aot_object.cpp) alike: LLVM's O3 pipeline with loop and SLP
// vectorization (no interleaving), and, in fast maths on x86, glibc's vector maths (libmvec;
// its 16-lane variants where the target has AVX-512F).
#pragma once

#include <llvm/IR/Module.h>
#include <llvm/Target/TargetMachine.h>

#include "codegen_llvm/jit_options.h"

namespace psys::codegen_llvm {

void optimizeModule(llvm::Module& module, llvm::TargetMachine& machine, MathMode mode, bool avx512);

// Code generation. Two parts of LLVM's grow faster than linearly: instruction selection
// with the size of a basic block, and register allocation at the higher levels with the
// calls in a function (each call clobbers the registers every live value must avoid). One
// equation of 2,000 `sin` terms took 14.6 s; cut and, past kLargeModule instructions,
// compiled with the fast allocator, it takes about 1.3 s a thousand terms — slower code,
// for kernels whose size, not their loop, is the cost. After optimizeModule, this cuts
// every basic block into blocks of at most 2·kBlock instructions joined by plain branches,
// and says whether the module is large: to be compiled at CodeGenOptLevel::None. What is
// fused into multiply-adds depends on both, so the JIT and AOT builds (one module a kernel
// each) do the same.
constexpr size_t kLargeModule = 4000, kBlock = 256;
bool prepareForCodegen(llvm::Module& module);

}  // namespace psys::codegen_llvm
