// Kernels compiled to machine code, called on the host: what the LLVM JIT (codegen_llvm/)
// and ahead-of-time compiled systems (native/aot_backend.h) share. The launch ABI of each
// compiled function, the key that names the code of a launch shape, and a backend that
// runs launches by calling code it is given — without LLVM, so that a program running an
// AOT-compiled system links none.
#pragma once

#include <cstdint>
#include <map>
#include <mutex>
#include <vector>

#include "ir/hash.h"
#include "ir/ir.h"
#include "rt/backend.h"
#include "rt/memory.h"

namespace psys::native {

// The version of an ahead-of-time build's table and of what its kernels read (psys_aot.abi,
// PSYS_AOT_ABI in include/psys/psys.h, which capi/aot.cpp checks is this): a build made
// under another is refused at open, never run. 3: an instance's record holds its externs;
// 4: an instanced program's updates also at per-row dt (instance speeds); 5: a fold's pair
// function walks its grid's buckets (rt::PairWalk).
constexpr uint32_t kAotAbi = 5;

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

// A launch of one kernel: its rows shape (clock sources) or children.
struct Shape {
    const ir::Kernel* kernel;
    bool children;
    rt::Clock::Source now, dt;
    bool operator<(const Shape& o) const {
        return std::tie(kernel, children, now, dt) < std::tie(o.kernel, o.children, o.now, o.dt);
    }
};

// What code a launch shape needs, and the key that names that code: a structural hash of
// the kernel, the launch shape, the column layout and the maths (equal keys, the same code).
struct Request {
    const ir::Object* object;
    Shape shape;
    const ir::Kernel* uniformKernel;  // rows with a per-row clock: evaluated per row
    bool vectorize;                   // a loop over many rows (false: a few, not vectorized)
    ir::Hash128 key;
};
Request request(bool exact, const ir::Object& o, const ir::Kernel& k, bool children, rt::Clock::Source now,
                rt::Clock::Source dt, bool many = true);

// Every request a module's systems make: its launch plan's, and its neighbour groups' pair
// kernels (compiled at their first fold).
std::vector<Request> requests(bool exact, const ir::Module& module);

// Runs launches by calling compiled code on columns in host memory; where the code comes
// from is the subclass's (`provide`).
class CompiledBackend : public rt::Backend {
public:
    explicit CompiledBackend(bool exact) : exact_(exact) {}
    rt::Memory& memory() override { return memory_; }
    void prepare(const rt::Plan& plan) override;
    void forget(const ir::Module& module) override;
    rt::RowsResult run(const rt::RowsLaunch& launch) override;
    void run(const rt::ChildrenLaunch& launch) override;
    void runChildren(std::span<const rt::ChildrenLaunch> launches) override;
    rt::PairFunction pairFunction(const ir::Object& object, const ir::Kernel& pair) override;
    bool concurrent() const override { return true; }
    bool marksDrawn() const override { return true; }  // render loops mark and count what they draw

protected:
    // Finds or makes the code of each request, and records it (`record`). Called without
    // the lock held.
    virtual void provide(const std::vector<Request>& requests) = 0;
    void record(const Shape& shape, void* code);

private:
    // The code for a launch shape (provided now if `prepare` did not list it).
    void* function(const ir::Object& o, const ir::Kernel& k, bool children, rt::Clock::Source now,
                   rt::Clock::Source dt);

    bool exact_;
    std::mutex mutex_;  // functions_: launches may come from several threads
    rt::HostMemory memory_;
    std::map<Shape, void*> functions_;  // the kernels of prepared modules
};

}  // namespace psys::native
