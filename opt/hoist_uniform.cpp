// hoist-uniform: work that is the same for every object of a type is done once.
//
// In the per-object kernels (update, render, exports) a value that depends only on
// constants, `dt`, `time` and externs is the same for every object evaluated with the
// same step. Such values move to a uniform kernel (`uniform.update`, …) that the run-time
// evaluates once per step per type — again only when a newly created object's first,
// partial update has another `dt` — and the per-object kernel reads them as
// `uniform #i`. Moving lanes around (splat, compose, extract, shuffle) costs nothing, so
// it stays behind; what it moves is hoisted.
#include <functional>

#include "ir/evaluate.h"
#include "opt/passes.h"
#include "opt/rewrite.h"

namespace psys::opt {

using namespace ir;

namespace {

bool freeLaneOp(Op op) { return op == Op::Splat || op == Op::Compose || op == Op::Extract || op == Op::Shuffle; }

void hoist(Object& object, KernelKind kind) {
    Kernel* k = object.kernel(kind);
    if (!k) return;
    std::vector<bool> uniform(k->size(), false);
    for (ValueId v = 0; v < k->size(); ++v) {
        const Inst& i = k->at(v);
        if (i.op == Op::Const || i.op == Op::Dt || i.op == Op::Time || i.op == Op::Extern) {
            uniform[v] = true;
        } else if (isPure(i.op)) {
            bool all = true;
            for (ValueId o : i.operands) all &= uniform[o];
            uniform[v] = all;
        }
    }
    // What to hoist: uniform values that cost something and that a per-object value or a
    // yield uses.
    std::vector<ValueId> hoisted;
    std::vector<int> index(k->size(), -1);
    std::function<void(ValueId)> take = [&](ValueId v) {
        const Inst& i = k->at(v);
        if (isLeaf(i.op) || index[v] >= 0) return;
        if (freeLaneOp(i.op)) {
            for (ValueId o : i.operands) take(o);
            return;
        }
        index[v] = static_cast<int>(hoisted.size());
        hoisted.push_back(v);
    };
    for (ValueId v = 0; v < k->size(); ++v)
        if (!uniform[v])
            for (ValueId o : k->at(v).operands)
                if (uniform[o]) take(o);
    for (const Yield& y : k->yields)
        if (uniform[y.value]) take(y.value);
    if (hoisted.empty()) return;

    Rewriter build(*k);
    Kernel u = build.run(nullptr, hoisted);
    u.kind = *uniformFor(kind);
    u.yields.clear();
    u.equations.clear();
    for (size_t i = 0; i < hoisted.size(); ++i)
        u.yields.push_back({YieldKind::Uniform, static_cast<int>(i), 0, build.map(hoisted[i])});

    Rewriter rw(*k);
    Kernel rest = rw.run([&](Rewriter& r, ValueId old, const Inst& inst, const std::vector<ValueId>&) -> std::optional<ValueId> {
        if (index[old] < 0) return std::nullopt;
        return r.emit(Inst::make(Op::Uniform, inst.type, {}, index[old]));
    });
    Rewriter clean(rest);  // the inputs only the hoisted values read are now unused
    *k = clean.run(nullptr);
    k->kind = kind;
    object.kernels.push_back(std::move(u));
}

}  // namespace

void hoistUniform(Module& module, PassErrors&) {
    for (Object& o : module.objects)
        for (KernelKind kind : {KernelKind::Update, KernelKind::Render, KernelKind::Exports}) hoist(o, kind);
}

}  // namespace psys::opt
