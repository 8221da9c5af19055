// LLVM functions for IR kernels, in the two launch shapes of rt/backend.h: a loop over a
// range of rows of a column table (RowsLaunch), and a spawn kernel over the children one
// object emits at once (ChildrenLaunch). Each builder adds one function to a module.
#pragma once

#include <cstdint>
#include <string>

#include <llvm/IR/Module.h>

#include "codegen_llvm/jit_options.h"
#include "ir/ir.h"
#include "native/compiled_backend.h"
#include "rt/backend.h"

namespace psys::codegen_llvm {

// The functions' signatures are native/compiled_backend.h's (RowsFn, ChildrenFn) and
// rt::PairFunction: the JIT and AOT builds make the same code.

// `lanes`: floats per vector register, the width the loop is vectorized to (0: not
// vectorized). `now` and `dt`: where the loop reads each row's clock from (rt/clock.h);
// when either is per row, the kernel's uniform kernel is evaluated in the loop for each row.
void buildRowsFunction(llvm::Module& module, MathMode mode, unsigned lanes, const ir::Object& object,
                       const ir::Kernel& kernel, const ir::Kernel* uniformKernel, rt::Clock::Source now,
                       rt::Clock::Source dt, const std::string& name);
void buildChildrenFunction(llvm::Module& module, MathMode mode, const ir::Object& object, const ir::Kernel& spawn,
                           const std::string& name);
// A neighbour group's walk and pair kernel as an rt::PairFunction (pair_function.cpp).
void buildPairFunction(llvm::Module& module, MathMode mode, const ir::Object& object, const ir::Kernel& pair,
                       const std::string& name);

// The function a request needs (rows, children or pair), and its name: what it is, for
// remarks and profiles (drop.update.created.7).
void buildFunction(llvm::Module& module, MathMode mode, unsigned lanes, const native::Request& request,
                   const std::string& name);
std::string functionName(const native::Request& request, int counter);

}  // namespace psys::codegen_llvm
