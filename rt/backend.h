// What the run-time asks of a backend: evaluate a kernel for one object (`run`), or for a
// range of rows of a pool, column by column (`runRows`, rt/batch.h).
//
// The run-time (pools, time, spawning, killing, parents, externs, triggers) is the same
// for every backend; a backend only computes kernels. For `run`, the inputs are gathered
// from the object's row of its pool and from the system; the yields come back in the
// kernel's order and the run-time scatters them. `runRows` reads and writes the pool's
// columns in place; its default runs `run` row by row, so every backend has it.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "ir/ir.h"
#include "ir/value.h"
#include "rt/batch.h"

namespace psys::rt {

using Value = ir::Value;

struct KernelInputs {
    const Value* params = nullptr;        // the object's (or a trigger's) parameters
    const Value* state = nullptr;         // its slots before this kernel
    const Value* externs = nullptr;
    const Value* uniforms = nullptr;      // the values of the kernel's uniform kernel
    float age = 0;
    float dt = 0;
    float time = 0;
    bool first = false;                   // true while the object is being created
    uint32_t seed = 0;
    uint32_t objectId = 0;
    uint32_t draw = 0;                    // draw.index #0: the step, or kCreationDraw
    uint32_t childDraw = 0;               // draw.index #1: the id of the object being spawned
    // Live reads of an ancestor `depth` levels up (1: the parent).
    std::function<Value(int depth, int exportIndex)> parentExport;
    std::function<bool(int depth)> parentAlive;
    std::function<float(int depth)> parentAge;
};

class Backend {
public:
    virtual ~Backend() = default;
    virtual std::string name() const = 0;
    // Evaluates `kernel` once; `yields[i]` receives the value of `kernel.yields[i]`.
    virtual void run(const ir::Kernel& kernel, const KernelInputs& in, std::vector<Value>& yields) = 0;

    // The arguments of `count` children that `in`'s object emits at once: a spawn kernel
    // run with childDraw firstChild, firstChild + 1, …; child k's argument `sub` goes to
    // args[k·stride + sub]. The default runs `run` once per child.
    virtual void runChildren(const ir::Kernel& spawn, const KernelInputs& in, uint32_t firstChild, size_t count,
                             Value* args, size_t stride);

    // What a System will ask of a backend for a module: the kernels it runs one object at
    // a time, and the loops it runs over rows. Called once, before any kernel of the
    // module runs, so a compiling backend compiles them all here (and anything else when
    // it is first asked for).
    struct Plan {
        std::vector<const ir::Kernel*> objectKernels;
        struct Loop {
            const ir::Object* object;
            const ir::Kernel* kernel;
            RowsMode mode;
        };
        std::vector<Loop> loops;
    };
    virtual void prepare(const Plan&) {}
    // The module's kernels are about to be destroyed: a backend that keeps anything by a
    // kernel's address drops it here (a later kernel may get the same address).
    virtual void forget(const ir::Module&) {}
    // Evaluates an update or exports kernel of `object` on the masked rows of `batch`.
    virtual void runRows(const ir::Object& object, const ir::Kernel& kernel, const BatchLayout& layout,
                         const RowBatch& batch);
    // Whether runRows may run on several threads at once (on disjoint rows).
    virtual bool concurrent() const { return false; }
};

}  // namespace psys::rt
