// Turns the instructions of one IR kernel into LLVM IR for one object, lane by lane.
//
// Every IR value becomes one LLVM scalar per component (float, i1 for bool, i32 for
// u32), never an LLVM vector: the loop over a pool's rows is what gets vectorized, eight
// objects to a register, and LLVM's loop vectorizer only widens scalar code. Vector
// operations of the IR (dot, compose, shuffle) are lane bookkeeping and cost nothing.
// The math modes are in jit_options.h.
#pragma once

#include <functional>

#include <llvm/ADT/SmallVector.h>
#include <llvm/IR/IRBuilder.h>
#include <llvm/IR/Module.h>

#include "codegen_llvm/jit_options.h"
#include "ir/ir.h"

namespace psys::codegen_llvm {

using Lanes = llvm::SmallVector<llvm::Value*, 4>;

// The lanes of an instruction that reads the world (parameters, state, externs, uniforms,
// age, dt, time, first, ids, draws, parent reads). `parentOrdinal` counts the kernel's
// parent reads in instruction order.
using LeafReader = std::function<Lanes(const ir::Inst& inst, int parentOrdinal)>;

// Emits `kernel` at the builder's insertion point; returns the lanes of every value.
// `seed` (i32) keys the random numbers; `externs` points at the externs' Values, the
// instance table after them (core/instances.h; null where the kernel can read none).
std::vector<Lanes> emitKernelBody(llvm::IRBuilder<>& builder, llvm::Module& module, const ir::Kernel& kernel,
                                  MathMode mode, llvm::Value* seed, llvm::Value* externs, const LeafReader& leaf);

// The LLVM type of one lane of an IR type.
llvm::Type* laneType(llvm::IRBuilder<>& builder, ir::Type type);

}  // namespace psys::codegen_llvm
