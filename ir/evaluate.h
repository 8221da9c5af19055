// What an IR kernel computes, as the reference: `evaluate` for one pure instruction (the
// interpreter and constant folding both use it, so folding a constant gives exactly what
// running it would), and `Evaluator` for a whole kernel given its inputs (the
// interpreter's loops, and the run-time's once-per-step kernels: start, triggers, uniform
// values). Lanes are computed by core/lanes.h, random draws by core/hash.h.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "ir/ir.h"
#include "ir/value.h"

namespace psys::ir {

// `operands[i]` is the value of `inst.operands[i]`, whose type is `operandTypes[i]`.
// For pure instructions only.
Value evaluate(const Inst& inst, const Value* operands, const Type* operandTypes);

// What a kernel reads when it is evaluated once.
struct KernelInputs {
    const Value* params = nullptr;    // param (the object's) or trigger.param (the trigger's)
    const Value* state = nullptr;     // the slots before this kernel
    const Value* externs = nullptr;
    const Value* uniforms = nullptr;  // the values of the kernel's uniform kernel
    const Value* parents = nullptr;   // the kernel's parent reads and folds, in instruction order
    const Value* self = nullptr;      // pair kernels: this object's exports, the other's
    const Value* other = nullptr;
    float age = 0;
    float dt = 0;
    float time = 0;
    bool first = false;               // true while the object is being created
    uint32_t seed = 0;
    uint32_t objectId = 0;
    uint32_t draw = 0;                // draw.index #0
    uint32_t childDraw = 0;           // draw.index #1: the id of the object being spawned
};

// Evaluates kernels instruction by instruction, in float, the way the IR says.
class Evaluator {
public:
    // `yields[i]` receives the value of `kernel.yields[i]`.
    void run(const Kernel& kernel, const KernelInputs& in, std::vector<Value>& yields);
    // The kernel once for each of `rows` (rows are independent: each gives what it would
    // alone, bit for bit); `yields[i * rows.size() + r]` receives row r's kernel.yields[i].
    // A batch of a few dozen rows pays the per-instruction dispatch once for them all.
    void run(const Kernel& kernel, std::span<const KernelInputs> rows, std::vector<Value>& yields);

private:
    std::vector<Value> registers_;
    std::vector<const Value*> operandRows_;
    std::vector<Type> operandTypes_;
};

// Whether Evaluator::run computes `op` (constants, the inputs, random draws, every pure
// op); for any other it throws ir::unexpectedOp's internal error, as every backend does.
bool evaluates(Op op);

// What the run-time gathers for a kernel (parent.export, parent.alive, parent.age, fold),
// in instruction order: the order of KernelInputs::parents.
std::vector<const Inst*> parentReads(const Kernel& kernel);

}  // namespace psys::ir
