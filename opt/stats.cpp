#include "opt/stats.h"

namespace psys::opt {

using namespace ir;

// Scalar operations: a vec3 addition is three, a dot product of vec3s five (three
// multiplications, two additions); moving lanes around (splat, compose, extract,
// shuffle) is free, as it is in registers.
namespace {

size_t opsOf(const Kernel& kernel, const Inst& i) {
    if (isLeaf(i.op)) return 0;
    switch (i.op) {
        case Op::Splat: case Op::Compose: case Op::Extract: case Op::Shuffle: return 0;
        case Op::Dot: return 2u * kernel.at(i.operands[0]).type.width - 1;
        case Op::Hash: return 8u * (kernel.at(i.operands[0]).type.width + i.type.width);  // (a PCG round each, ~8 ops)
        case Op::Eq: case Op::Ne: return kernel.at(i.operands[0]).type.width;
        default: return i.type.width;
    }
}

}  // namespace

size_t countOps(const Kernel& kernel) {
    size_t n = 0;
    for (const Inst& i : kernel.insts()) n += opsOf(kernel, i);
    return n;
}

size_t countTreeOps(const Kernel& kernel) {
    std::vector<size_t> tree(kernel.size(), 0);
    for (ValueId v = 0; v < kernel.size(); ++v) {
        const Inst& i = kernel.at(v);
        tree[v] = opsOf(kernel, i);
        for (ValueId o : i.operands) tree[v] += tree[o];
    }
    size_t n = 0;
    for (const Yield& y : kernel.yields) n += tree[y.value];
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
            if (perFrame) c.treeOpsPerUpdate += countTreeOps(k);
        }
        for (const StateSlot& s : o.state) c.stateBytes += 4u * s.type.width;
        for (const Param& p : o.params)
            if (p.kept) c.paramBytes += 4u * p.type.width;
        out.push_back(c);
    }
    return out;
}

}  // namespace psys::opt
