// resolve-cycles: recursive equations become state (thesis §3.1.5, §4.3.3–4.3.4).
//
// Lowering evaluates an object's equations in dependency order and writes each
// reference to an equation evaluated later as `recur %x`: a reference that closes a
// cycle. Such a cycle has a value only if it passes through something with a value of
// its own at the start (`integrate`, `prev`, the `next` side of `->`): then `recur %x`
// means x at the previous update, i.e. `prev %x`, which lower-temporal makes a state
// slot. A cycle that does not is an algebraic loop, reported with its path. (The front
// end reports those on the source already; this check keeps the IR honest on its own.)
//
// That is the default method's reading (semi_implicit). The other integration methods
// solve an object's integrals as one system, in which an integrand reads the values of
// the same instant: a cycle that runs through an `integrate` or a `prev` keeps its
// `recur`, which lower-temporal resolves to the equation's value at each stage and at the
// end of the update. Only a cycle through `->` alone still means the previous update.
#include <fmt/format.h>

#include "opt/passes.h"

namespace psys::opt {

using namespace ir;

namespace {

// A path from `from` to `target` along operands that are used in the same update (not
// through delaying operands, or with `stageLeaves`, not through the operand of an
// `integrate` or a `prev`), or empty.
std::vector<ValueId> immediatePath(const Kernel& k, ValueId from, ValueId target, bool stageLeaves = false) {
    std::vector<int> parent(k.size(), -2);
    std::vector<ValueId> work = {from};
    parent[from] = -1;
    while (!work.empty()) {
        ValueId v = work.back();
        work.pop_back();
        if (v == target) {
            std::vector<ValueId> path;
            for (int p = static_cast<int>(v); p >= 0; p = parent[static_cast<size_t>(p)]) path.push_back(static_cast<ValueId>(p));
            return {path.rbegin(), path.rend()};
        }
        const Inst& inst = k.at(v);
        for (size_t i = 0; i < inst.operands.size(); ++i) {
            ValueId o = inst.operands[i];
            bool delayed = stageLeaves ? inst.op == Op::Integrate || inst.op == Op::Prev : mayReferForward(inst.op, i);
            if (delayed || parent[o] != -2) continue;
            parent[o] = static_cast<int>(v);
            work.push_back(o);
        }
    }
    return {};
}

}  // namespace

void resolveCycles(Module& module, const PassOptions& options, PassErrors& errors) {
    for (Object& object : module.objects) {
        Kernel* k = object.kernel(KernelKind::Behaviour);
        if (!k) continue;
        Integrator method = methodOf(object, options);
        for (ValueId v = 0; v < k->size(); ++v) {
            if (k->at(v).op != Op::Recur) continue;
            std::vector<ValueId> loop = immediatePath(*k, k->at(v).operands[0], v);
            if (!loop.empty()) {
                std::string path;
                for (ValueId p : loop) {
                    const std::string& n = k->at(p).name;
                    path += (path.empty() ? "" : " → ") + (n.empty() ? fmt::format("%{}", p) : n);
                }
                errors.error(k->at(v).loc, fmt::format("object {}: algebraic loop: {} → {}", object.name,
                                             k->at(v).name.empty() ? fmt::format("%{}", v) : k->at(v).name, path));
                continue;
            }
            bool throughIntegral = method != Integrator::SemiImplicit &&
                                   immediatePath(*k, k->at(v).operands[0], v, true).empty();
            if (!throughIntegral) k->mutableAt(v).op = Op::Prev;
        }
    }
}

}  // namespace psys::opt
