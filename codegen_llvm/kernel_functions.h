// LLVM functions for IR kernels, in the three shapes the run-time calls: one object
// (`run`), the children an object emits at once (`runChildren`), and a loop over a range
// of a pool's rows (`runRows`). Each builder adds one function to a module.
#pragma once

#include <cstdint>
#include <string>

#include <llvm/IR/Module.h>

#include "codegen_llvm/jit_options.h"
#include "ir/ir.h"
#include "rt/backend.h"

namespace psys::codegen_llvm {

// void kernel(const Value* params, const Value* state, const Value* externs,
//             const Value* uniforms, const Value* parents, const float* scalars,
//             const uint32_t* keys, Value* yields)
// scalars: age, dt, time, first; keys: seed, object id, draw, child draw; parents: the
// values of the kernel's parent reads, gathered by the caller in instruction order.
using ObjectFn = void (*)(const rt::Value*, const rt::Value*, const rt::Value*, const rt::Value*, const rt::Value*,
                          const float*, const uint32_t*, rt::Value*);

// The spawn kernel over several children (ObjectFunctionBuilder::buildChildren).
using ChildrenFn = void (*)(const rt::Value*, const rt::Value*, const rt::Value*, const rt::Value*, const rt::Value*,
                            const float*, const uint32_t*, rt::Value*, int64_t, int64_t);

// void rows(void* const* columns, const uint8_t* mask, int64_t begin, int64_t end,
//           const Value* externs, const Value* uniforms, double time, float dt,
//           uint32_t seed, uint32_t draw)
using RowsFn = void (*)(void* const*, const uint8_t*, int64_t, int64_t, const rt::Value*, const rt::Value*, double,
                        float, uint32_t, uint32_t);


void buildObjectFunction(llvm::Module& module, MathMode mode, const ir::Kernel& kernel, const std::string& name);
void buildChildrenFunction(llvm::Module& module, MathMode mode, const ir::Kernel& kernel, const std::string& name);
// `lanes`: floats per vector register, the width the loop is vectorized to.
void buildRowsFunction(llvm::Module& module, MathMode mode, unsigned lanes, const ir::Object& object,
                       const ir::Kernel& kernel, rt::RowsMode rowsMode, const std::string& name);

}  // namespace psys::codegen_llvm
