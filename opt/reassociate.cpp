// reassociate (relaxed maths only): sums and products in one canonical order.
//
// Thesis §4.3.8 could not share a+b between (a+b+c)·(a+b+d) written in other orders. Here
// a chain of additions (or of multiplications) of one type, whose inner links have no
// other use, is flattened into its terms, the terms are sorted by value number, and the
// chain is rebuilt left to right: (c+a+b) and (b+a+d) become (a+b)+c and (a+b)+d, and
// hash-consing then computes a+b once. Floating-point addition is not associative, so
// the result may differ in the last bits (docs/optimizer.md gives the bound).
#include <algorithm>
#include <functional>

#include "opt/passes.h"
#include "opt/rewrite.h"

namespace psys::opt {

using namespace ir;

namespace {

void reassociateKernel(Kernel& kernel) {
    std::vector<int> users(kernel.size(), 0);
    for (const Inst& i : kernel.insts())
        for (ValueId o : i.operands) ++users[o];
    for (const Yield& y : kernel.yields) ++users[y.value];
    for (auto& [name, v] : kernel.equations) ++users[v];

    // The terms of the chain rooted at `v` (old values), left to right.
    std::function<void(ValueId, Op, Type, bool, std::vector<ValueId>&)> terms =
        [&](ValueId v, Op op, Type t, bool root, std::vector<ValueId>& out) {
            const Inst& i = kernel.at(v);
            if (i.op == op && i.type == t && (root || users[v] == 1)) {
                for (ValueId o : i.operands) terms(o, op, t, false, out);
                return;
            }
            out.push_back(v);
        };
    Rewriter rw(kernel);
    Kernel result = rw.run([&](Rewriter& r, ValueId old, const Inst& inst, const std::vector<ValueId>&) -> std::optional<ValueId> {
        if (inst.op != Op::Add && inst.op != Op::Mul) return std::nullopt;
        std::vector<ValueId> leaves;
        terms(old, inst.op, inst.type, true, leaves);
        if (leaves.size() < 3) return std::nullopt;
        std::vector<ValueId> mapped;
        for (ValueId l : leaves) mapped.push_back(r.map(l));
        std::sort(mapped.begin(), mapped.end());
        ValueId acc = mapped[0];
        for (size_t i = 1; i < mapped.size(); ++i) acc = r.emit(Inst::make(inst.op, inst.type, {acc, mapped[i]}));
        return acc;
    });
    result.kind = kernel.kind;
    result.site = kernel.site;
    kernel = std::move(result);
}

}  // namespace

void reassociate(Module& module, PassErrors&) {
    for (Object& o : module.objects) {
        if (o.attributes.precision == Precision::Double) continue;  // pair arithmetic is exact only in its order
        for (Kernel& k : o.kernels) reassociateKernel(k);
    }
}

}  // namespace psys::opt
