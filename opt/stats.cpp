#include "opt/stats.h"

namespace psys::opt {

using namespace ir;

size_t countOps(const Kernel& kernel) {
    size_t n = 0;
    for (const Inst& i : kernel.insts()) n += isInput(i.op) ? 0 : 1;
    return n;
}

std::vector<ObjectCost> measure(const Module& module) {
    std::vector<ObjectCost> out;
    for (const Object& o : module.objects) {
        ObjectCost c;
        c.name = o.name;
        for (const Kernel& k : o.kernels) {
            bool perFrame = k.kind == KernelKind::Update || k.kind == KernelKind::Render || k.kind == KernelKind::Exports;
            (perFrame ? c.opsPerUpdate : c.opsAtCreation) += countOps(k);
        }
        for (const StateSlot& s : o.state) c.stateBytes += 4u * s.type.width;
        for (const Param& p : o.params)
            if (p.kept) c.paramBytes += 4u * p.type.width;
        out.push_back(c);
    }
    return out;
}

}  // namespace psys::opt
