// key-random: every random draw gets an explicit key (thesis §3.1.4).
//
// `rand #site` becomes `rand %id, %draw #site`: a counter-based generator hashes
// (seed, object id, call site, draw index) — no generator state, so any backend, any
// thread order and the GPU draw the same numbers. The draw index says which evaluation
// this is: `draw.index #0` is the current one (the update's step number, or creation),
// `draw.index #1` the object being spawned, for draws written in emit arguments (one per
// created object). The run-time supplies both.
#include "opt/passes.h"
#include "opt/rewrite.h"

namespace psys::opt {

using namespace ir;

namespace {

void keyKernel(Kernel& k) {
    bool any = false;
    for (const Inst& inst : k.insts()) any |= (inst.op == Op::Rand || inst.op == Op::NRand) && inst.operands.empty();
    if (!any) return;
    Rewriter rewriter(k);
    k = rewriter.run([](Rewriter& rw, ValueId, const Inst& inst, const std::vector<ValueId>&) -> std::optional<ValueId> {
        if ((inst.op != Op::Rand && inst.op != Op::NRand) || !inst.operands.empty()) return std::nullopt;
        Inst id = Inst::make(Op::ObjectId, Type::u32(), {});
        Inst draw = Inst::make(Op::DrawIndex, Type::u32(), {}, inst.attr2 == 1 ? 1 : 0);
        Inst keyed = inst;
        keyed.operands = {rw.emit(id), rw.emit(draw)};
        keyed.attr2 = 0;
        return rw.emit(std::move(keyed));
    });
}

}  // namespace

void keyRandom(Module& module, PassErrors&) {
    for (Object& object : module.objects)
        for (Kernel& k : object.kernels) keyKernel(k);
    for (Trigger& t : module.triggers) keyKernel(t.kernel);
    keyKernel(module.start.kernel);
}

}  // namespace psys::opt
