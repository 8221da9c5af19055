// lower-storage: what the run-time stores for each kernel, fixed by the compiler.
//
// A kernel's launches read and write columns beyond its object's declared state,
// parameters and exports, and which ones depends on its values: an emission rate that is
// a constant, an extern or a uniform value is the same in every row (the run-time takes
// it from there, and a device need not send the column back); a drawn position that is a
// state slot as it is is drawn from the state column, a colour lane that is a constant
// needs no column at all; every parent read is a column the run-time gathers; a new
// object's state that its init does not set must be zeroed before it runs. This pass
// decides all of it once, as the last pass, and records it on the kernel
// (ir::KernelStorage, printed as `storage` lines): rt::columnLayout turns the record into
// column positions, and neither the run-time nor a backend looks at the instructions to
// find it out. Only what it records changes; no instruction does.
#include <optional>

#include "opt/passes.h"

namespace psys::opt {
namespace {

using namespace ir;

// Lane `lane` of `v` when it is a constant: a constant, a splat of one, or a lane of a
// compose that is.
std::optional<float> constantLane(const Kernel& k, ValueId v, int lane) {
    const Inst& i = k.at(v);
    switch (i.op) {
        case Op::Const: return i.type.isBool() ? std::nullopt : std::optional<float>(i.constant[static_cast<size_t>(lane)]);
        case Op::Splat: return constantLane(k, i.operands[0], 0);
        case Op::Compose:
            for (ValueId o : i.operands) {
                int width = k.at(o).type.width;
                if (lane < width) return constantLane(k, o, lane);
                lane -= width;
            }
            return std::nullopt;
        default: return std::nullopt;
    }
}

KernelStorage storageOf(const Object& object, const Kernel& kernel) {
    KernelStorage st;
    st.fixed = true;
    st.emits.assign(2 * object.emits.size(), {});
    for (const Yield& y : kernel.yields) {
        if (y.kind != YieldKind::EmitRate && y.kind != YieldKind::EmitCount) continue;
        auto column = static_cast<size_t>(2 * y.index + (y.kind == YieldKind::EmitCount ? 1 : 0));
        if (column >= st.emits.size()) continue;  // (the verifier's to report)
        const Inst& value = kernel.at(y.value);
        using From = KernelStorage::Shared::From;
        if (value.op == Op::Const) st.emits[column] = {From::Constant, 0, value.constant[0]};
        if (value.op == Op::Extern) st.emits[column] = {From::Extern, value.attr, 0};
        if (value.op == Op::Uniform) st.emits[column] = {From::Uniform, value.attr, 0};
    }
    if (kernel.kind == KernelKind::Render) {
        st.drawn.assign(static_cast<size_t>(renderColumns(object)), {});
        using From = KernelStorage::Drawn::From;
        for (const Yield& y : kernel.yields) {
            if (!isDrawnYield(y.kind) || y.kind == YieldKind::Visible) continue;
            const Inst& value = kernel.at(y.value);
            int first = drawnColumn(y.kind, y.index);
            for (int c = 0; c < value.type.width; ++c) {
                KernelStorage::Drawn& d = st.drawn[static_cast<size_t>(first + c)];
                if (value.op == Op::StateRead) d = {From::State, value.attr, c, 0};
                else if (auto k = constantLane(kernel, y.value, c)) d = {From::Constant, 0, 0, *k};
            }
        }
    }
    for (const Inst& i : kernel.insts())
        if (isGathered(i.op))
            st.parents.push_back({i.op, i.attr2, i.op == Op::ParentExport || i.op == Op::Fold ? i.attr : -1, i.type.width});
    if (kernel.kind == KernelKind::Init) {
        std::vector<bool> set(object.state.size(), false);
        bool readsState = false;
        for (const Inst& i : kernel.insts()) readsState |= i.op == Op::StateRead;
        for (const Yield& y : kernel.yields)
            if (!readsState && y.kind == YieldKind::StateNext) set.at(static_cast<size_t>(y.index)) = true;
        for (size_t slot = 0; slot < set.size(); ++slot)
            if (!set[slot]) st.zeroed.push_back(static_cast<int>(slot));
    }
    return st;
}

}  // namespace

void lowerStorage(Module& module, PassErrors&) {
    for (Object& object : module.objects)
        for (Kernel& kernel : object.kernels) {
            kernel.storage = storageOf(object, kernel);
            defaultDrawn(kernel);
        }
}

}  // namespace psys::opt
