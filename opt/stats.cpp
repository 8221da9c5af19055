#include "opt/stats.h"

namespace psys::opt {

using namespace ir;

// Scalar operations: a vec3 addition is three, a dot product of vec3s five (three
// multiplications, two additions); moving lanes around (splat, compose, extract,
// shuffle) is free, as it is in registers.
size_t countOps(const Kernel& kernel) {
    size_t n = 0;
    for (const Inst& i : kernel.insts()) {
        if (isInput(i.op)) continue;
        switch (i.op) {
            case Op::Splat: case Op::Compose: case Op::Extract: case Op::Shuffle: break;
            case Op::Dot: n += 2u * kernel.at(i.operands[0]).type.width - 1; break;
            case Op::Eq: case Op::Ne: n += kernel.at(i.operands[0]).type.width; break;
            default: n += i.type.width; break;
        }
    }
    return n;
}

std::vector<ObjectCost> measure(const Module& module) {
    std::vector<ObjectCost> out;
    for (const Object& o : module.objects) {
        ObjectCost c;
        c.name = o.name;
        for (const Kernel& k : o.kernels) {
            bool perFrame = k.kind == KernelKind::Update || k.kind == KernelKind::Render || k.kind == KernelKind::Exports;
            bool uniform = k.kind == KernelKind::UniformUpdate || k.kind == KernelKind::UniformRender ||
                           k.kind == KernelKind::UniformExports;
            (uniform ? c.uniformOps : perFrame ? c.opsPerUpdate : c.opsAtCreation) += countOps(k);
        }
        for (const StateSlot& s : o.state) c.stateBytes += 4u * s.type.width;
        for (const Param& p : o.params)
            if (p.kept) c.paramBytes += 4u * p.type.width;
        out.push_back(c);
    }
    return out;
}

}  // namespace psys::opt
