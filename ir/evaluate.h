// What each pure instruction computes: one definition, used by the interpreter and by
// constant folding, so folding a constant gives exactly what running it would.
#pragma once

#include <vector>

#include "ir/ir.h"
#include "ir/value.h"

namespace psys::ir {

// Whether `evaluate` computes `op` (arithmetic, logic and vector instructions; not inputs,
// random draws or temporal constructs).
bool isPure(Op op);

// `operands[i]` is the value of `inst.operands[i]`, whose type is `operandTypes[i]`.
Value evaluate(const Inst& inst, const Value* operands, const Type* operandTypes);

}  // namespace psys::ir
