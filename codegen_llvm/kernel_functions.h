// LLVM functions for IR kernels, in the two launch shapes of rt/backend.h: a loop over a
// range of rows of a column table (RowsLaunch), and a spawn kernel over the children one
// object emits at once (ChildrenLaunch). Each builder adds one function to a module.
#pragma once

#include <cstdint>
#include <string>

#include <llvm/IR/Module.h>

#include "codegen_llvm/jit_options.h"
#include "ir/ir.h"
#include "rt/backend.h"

namespace psys::codegen_llvm {

// RowCounts rows(void* const* columns, const uint8_t* mask, int64_t begin, int64_t end,
//                const Value* externs, const Value* uniforms, double now, float dt,
//                uint32_t first, uint32_t seed, uint32_t draw)
// `columns`: host addresses by layout position. Returns the rows it killed and the rows
// it found beyond the integration method's stability limit — for a render kernel, which
// marks its rows drawn itself, the rows drawn and the rows visible but not finite (an
// LLVM {i64, i64}: two registers, as the C ABI returns this struct).
struct RowCounts {
    int64_t killed;    // render: drawn
    int64_t unstable;  // render: not drawn for a NaN or an infinity
};
using RowsFn = RowCounts (*)(void* const*, const uint8_t*, int64_t, int64_t, const rt::Value*, const rt::Value*, double,
                             float, uint32_t, uint32_t, uint32_t);

// void children(void* const* columns, int64_t row, const Value* parents, const Value* externs,
//               double now, float dt, uint32_t first, uint32_t seed, uint32_t draw,
//               uint32_t firstChild, int64_t count, float* const* args, int64_t argsFirst)
using ChildrenFn = void (*)(void* const*, int64_t, const rt::Value*, const rt::Value*, double, float, uint32_t,
                            uint32_t, uint32_t, uint32_t, int64_t, float* const*, int64_t);

// `lanes`: floats per vector register, the width the loop is vectorized to (0: not
// vectorized). `now` and `dt`: where the loop reads each row's clock from (rt/clock.h);
// when either is per row, the kernel's uniform kernel is evaluated in the loop for each row.
void buildRowsFunction(llvm::Module& module, MathMode mode, unsigned lanes, const ir::Object& object,
                       const ir::Kernel& kernel, const ir::Kernel* uniformKernel, rt::Clock::Source now,
                       rt::Clock::Source dt, const std::string& name);
void buildChildrenFunction(llvm::Module& module, MathMode mode, const ir::Object& object, const ir::Kernel& spawn,
                           const std::string& name);
// A neighbour group's pair kernel as an rt::PairFunction (pair_function.cpp).
void buildPairFunction(llvm::Module& module, MathMode mode, const ir::Object& object, const ir::Kernel& pair,
                       const std::string& name);

}  // namespace psys::codegen_llvm
