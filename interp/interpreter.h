// The reference backend: evaluates IR kernels instruction by instruction, in float, the
// way the IR says. Slow and obviously right; every other backend is tested against it.
#pragma once

#include "rt/backend.h"

namespace psys::interp {

class Interpreter : public rt::Backend {
public:
    std::string name() const override { return "interp"; }
    void run(const ir::Kernel& kernel, const rt::KernelInputs& in, std::vector<rt::Value>& yields) override;

private:
    std::vector<rt::Value> registers_;
    std::vector<rt::Value> operandValues_;
    std::vector<ir::Type> operandTypes_;
};

}  // namespace psys::interp
