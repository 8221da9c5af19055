#include "opt/rewrite.h"

#include <set>

namespace psys::opt {

using namespace ir;

namespace {

std::optional<bool> constantBool(const Kernel& k, ValueId v) {
    const Inst& i = k.at(v);
    if (i.op != Op::Const || !i.type.isBool()) return std::nullopt;
    return i.constant[0] != 0;
}

}  // namespace

ValueId zeroOf(Kernel& k, Type t) {
    if (t.isBool()) return k.boolean(false);
    return k.constant(t, {0, 0, 0, 0});
}

bool creationInvariant(const Kernel& k, ValueId v) {
    const Inst& i = k.at(v);
    if (i.op == Op::Param || i.op == Op::Const) return true;
    if (!isPure(i.op)) return false;
    for (ValueId o : i.operands)
        if (!creationInvariant(k, o)) return false;
    return true;
}

ValueId Rewriter::emit(Inst inst) {
    auto c = [&](size_t i) { return constantBool(to_, inst.operands[i]); };
    switch (inst.op) {
        case Op::Select:
            if (auto cond = c(0)) return inst.operands[*cond ? 1 : 2];
            if (inst.operands[1] == inst.operands[2]) return inst.operands[1];
            break;
        case Op::And:
            for (size_t i = 0; i < 2; ++i)
                if (auto b = c(i)) return *b ? inst.operands[1 - i] : to_.boolean(false);
            break;
        case Op::Or:
            for (size_t i = 0; i < 2; ++i)
                if (auto b = c(i)) return *b ? to_.boolean(true) : inst.operands[1 - i];
            break;
        case Op::Not:
            if (auto b = c(0)) return to_.boolean(!*b);
            break;
        default: break;
    }
    return hasOwnSite(inst.op) ? to_.addUnique(std::move(inst)) : to_.add(std::move(inst));
}

Kernel Rewriter::run(const Hook& hook) {
    std::vector<ValueId> roots;
    for (const Yield& y : from_.yields) roots.push_back(y.value);
    for (auto& [name, v] : from_.equations) roots.push_back(v);
    return run(hook, roots);
}

Kernel Rewriter::run(const Hook& hook, const std::vector<ValueId>& roots) {
    to_ = Kernel();
    to_.kind = from_.kind;
    to_.site = from_.site;
    mapped_.clear();
    // Live: what the roots use, through every operand (forward ones included).
    std::vector<bool> live(from_.size(), false);
    std::vector<ValueId> work(roots.begin(), roots.end());
    while (!work.empty()) {
        ValueId v = work.back();
        work.pop_back();
        if (live[v]) continue;
        live[v] = true;
        for (ValueId o : from_.at(v).operands) work.push_back(o);
    }
    std::vector<std::pair<ValueId, size_t>> forward;  // (new instruction, operand) to patch
    std::vector<std::pair<ValueId, ValueId>> forwardOld;
    for (ValueId v = 0; v < from_.size(); ++v) {
        if (!live[v]) continue;
        const Inst& inst = from_.at(v);
        std::vector<ValueId> operands;
        std::vector<size_t> pending;
        for (size_t i = 0; i < inst.operands.size(); ++i) {
            ValueId o = inst.operands[i];
            if (mapped_.count(o)) {
                operands.push_back(mapped_[o]);
            } else {  // a forward reference: patched below
                operands.push_back(0);
                pending.push_back(i);
            }
        }
        // What the hook builds stands for `inst`: it gets its location.
        LocScope at(to_, inst.loc);
        std::optional<ValueId> replaced = hook ? hook(*this, v, inst, operands) : std::nullopt;
        ValueId nv;
        if (replaced) {
            nv = *replaced;
        } else {
            Inst copy = inst;
            copy.operands = operands;
            nv = pending.empty() ? emit(std::move(copy)) : to_.addUnique(std::move(copy));
            for (size_t i : pending) {
                forward.push_back({nv, i});
                forwardOld.push_back({nv, inst.operands[i]});
            }
        }
        if (!inst.name.empty() && to_.at(nv).name.empty() && !isLeaf(to_.at(nv).op)) to_.mutableAt(nv).name = inst.name;
        mapped_[v] = nv;
    }
    for (size_t i = 0; i < forward.size(); ++i)
        to_.mutableAt(forward[i].first).operands[forward[i].second] = mapped_.at(forwardOld[i].second);
    if (!forward.empty()) to_.rehash();
    for (const Yield& y : from_.yields)
        if (mapped_.count(y.value)) to_.yields.push_back({y.kind, y.index, y.sub, mapped_[y.value]});
    for (auto& [name, v] : from_.equations)
        if (mapped_.count(v)) to_.equations[name] = mapped_[v];
    return std::move(to_);
}

}  // namespace psys::opt
