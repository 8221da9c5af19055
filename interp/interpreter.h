// The reference backend: evaluates IR kernels instruction by instruction, in float, the
// way the IR says (ir::Evaluator), each row on its own over host memory (rows are handed
// to the evaluator in batches, which pays its dispatch once per instruction and batch and
// changes no bit). Slow and obviously right; every other backend is tested against it.
#pragma once

#include <vector>

#include "ir/evaluate.h"
#include "rt/backend.h"

namespace psys::interp {

struct Columns;  // a launch's columns on host memory (interpreter.cpp)

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
    // Rows an evaluation (measured on tornado, galaxy, shapes: 1.5–1.7× faster than 16;
    // 64 and 1024 slower than 256).
    static constexpr size_t kBatch = 256;
    void store(const rt::RowsLaunch& launch, const Columns& columns, uint8_t* kill, size_t row, size_t batchRow,
               size_t batchSize, rt::RowsResult& result) const;

    rt::HostMemory own_;
    rt::Memory* memory_ = &own_;
    ir::Evaluator evaluator_;
    std::vector<rt::Value> params_, state_, parents_, uniforms_, yields_;
    std::vector<ir::KernelInputs> inputs_, uniformInputs_;
    std::vector<size_t> batchRows_;
    rt::ArgumentColumns arguments_;  // a children launch's (kept, as the vectors above, from launch to launch)
};

}  // namespace psys::interp
