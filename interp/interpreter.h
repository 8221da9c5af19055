// The reference backend: evaluates IR kernels instruction by instruction, in float, the
// way the IR says (ir::Evaluator), one row at a time over host memory. Slow and obviously
// right; every other backend is tested against it.
#pragma once

#include <vector>

#include "ir/evaluate.h"
#include "rt/backend.h"

namespace psys::interp {

class Interpreter : public rt::Backend {
public:
    // Over its own host memory.
    Interpreter() = default;
    // Over another backend's memory, whose columns it reads and writes through `host`
    // (a GPU backend's small pools whose columns are on the host: GlslBackend::setHostSide).
    explicit Interpreter(rt::Memory& memory) : memory_(&memory) {}
    std::string name() const override { return "interp"; }
    rt::Memory& memory() override { return *memory_; }
    // Refuses a kernel with an op it cannot run (ir::unexpectedOp), before any launch.
    void prepare(const rt::Plan& plan) override;
    rt::RowsResult run(const rt::RowsLaunch& launch) override;
    void run(const rt::ChildrenLaunch& launch) override;
    rt::BackendReport report() const override;

private:
    rt::HostMemory own_;
    rt::Memory* memory_ = &own_;
    ir::Evaluator evaluator_;
    std::vector<rt::Value> params_, state_, parents_, uniformValues_, uniforms_, yields_;
};

}  // namespace psys::interp
