#include "opt/integrate_step.h"

#include <stdexcept>

#include "opt/rewrite.h"

namespace psys::opt {

using namespace ir;

StepBuilder::StepBuilder(const Kernel& from, std::vector<ValueId> integrals, std::vector<int> slots)
    : from_(from), integrals_(std::move(integrals)), slots_(std::move(slots)), dependent_(from.size(), false) {
    for (size_t j = 0; j < integrals_.size(); ++j) integralIndex_[integrals_[j]] = j;
    to_.kind = from.kind;
    // What changes within the step; `recur` may refer forward, hence the fixpoint.
    for (bool changed = true; changed;) {
        changed = false;
        for (ValueId v = 0; v < from.size(); ++v) {
            if (dependent_[v]) continue;
            const Inst& i = from.at(v);
            bool d = i.op == Op::Integrate || i.op == Op::Age || i.op == Op::Time;
            for (ValueId o : i.operands) d |= i.op != Op::Integrate && dependent_[o];
            if (d) dependent_[v] = changed = true;
        }
    }
}

ValueId StepBuilder::resolve(ValueId old) const {
    while (from_.at(old).op == Op::Recur) old = from_.at(old).operands[0];
    return old;
}

std::set<size_t> StepBuilder::reads(size_t j) const {
    std::set<size_t> found;
    std::set<ValueId> seen;
    std::vector<ValueId> work = {derivative(j)};
    while (!work.empty()) {
        ValueId v = resolve(work.back());
        work.pop_back();
        if (!dependent_[v] || !seen.insert(v).second) continue;
        if (auto i = integralIndex_.find(v); i != integralIndex_.end()) {
            found.insert(i->second);
            continue;
        }
        if (from_.at(v).op == Op::Integrate) continue;  // not one of the system's
        for (ValueId o : from_.at(v).operands) work.push_back(o);
    }
    return found;
}

bool StepBuilder::fixedAtCreation(ValueId old) const {
    const Inst& i = from_.at(old);
    if (i.op == Op::Param || i.op == Op::Const || snapshotsOfFixed_.count(old)) return true;
    if (!isPure(i.op)) return false;
    for (ValueId o : i.operands)
        if (!fixedAtCreation(o)) return false;
    return true;
}

ValueId StepBuilder::dt() { return to_.add(Inst::make(Op::Dt, Type::f32())); }

ValueId StepBuilder::start(size_t j) { return to_.add(Inst::make(Op::StateRead, type(j), {}, slots_[j])); }

// The inputs hold the end of the update: back by (1 − c)·dt, or by dt − since.
ValueId StepBuilder::clockAt(Op input, const Point& point) {
    ValueId end = to_.add(Inst::make(input, Type::f32()));
    if (point.since) return to_.op(Op::Sub, Type::f32(), {end, to_.op(Op::Sub, Type::f32(), {dt(), *point.since})});
    float c = point.c;
    if (c == 1) return end;
    ValueId behind = c == 0 ? dt() : to_.op(Op::Mul, Type::f32(), {scalar(1 - c), dt()});
    return to_.op(Op::Sub, Type::f32(), {end, behind});
}

StepBuilder::Point& StepBuilder::startPoint() {
    if (start_.empty()) {
        std::vector<ValueId> y;
        for (size_t j = 0; j < size(); ++j) y.push_back(start(j));
        start_.push_back(pointAt(0, std::move(y)));
    }
    return start_.front();
}

ValueId StepBuilder::copy(ValueId old, const std::function<ValueId(ValueId)>& operand) {
    Inst inst = from_.at(old);
    for (ValueId& o : inst.operands) o = operand(o);
    return hasOwnSite(inst.op) ? to_.addUnique(std::move(inst)) : to_.add(std::move(inst));
}

ValueId StepBuilder::at(Point& point, ValueId old) {
    if (!dependent_[old]) return final(old);
    if (auto j = integralIndex_.find(old); j != integralIndex_.end()) return point.y[j->second];
    if (auto it = point.values.find(old); it != point.values.end()) return it->second;
    ValueId v;
    const Inst& i = from_.at(old);
    if (auto seen = stageViews_.find(old); seen != stageViews_.end()) v = final(seen->second);
    else if (i.op == Op::Age || i.op == Op::Time) v = clockAt(i.op, point);
    else if (i.op == Op::Recur) v = at(point, i.operands[0]);
    else v = copy(old, [&](ValueId o) { return at(point, o); });
    return point.values[old] = v;
}

ValueId StepBuilder::final(ValueId old) {
    if (auto it = final_.find(old); it != final_.end()) return it->second;
    ValueId v;
    const Inst& i = from_.at(old);
    if (auto j = integralIndex_.find(old); j != integralIndex_.end()) {
        if (solved_.empty()) {
            // A method reads only the start of the step and its stages, never an
            // integral's final value: a request while solving is a bug in the method.
            if (solving_ || !solve_) throw std::logic_error("an integration method read the value it computes");
            solving_ = true;
            solved_ = (*solve_)(*this);
            solving_ = false;
        }
        LocScope here(to_, i.loc);
        ValueId first = to_.add(Inst::make(Op::First, Type::boolean()));
        v = to_.add(Inst::make(Op::Select, i.type, {first, zeroOf(to_, i.type), solved_.at(j->second)}));
    } else if (i.op == Op::Recur) {
        v = final(i.operands[0]);
    } else {
        v = copy(old, [&](ValueId o) { return final(o); });
    }
    return final_[old] = v;
}

void StepBuilder::run(const Solve& solve) {
    solve_ = &solve;
    for (const Yield& y : from_.yields) to_.yields.push_back({y.kind, y.index, y.sub, final(y.value)});
    for (auto& [name, v] : from_.equations) to_.equations[name] = final(v);
    solve_ = nullptr;
}

Kernel StepBuilder::take() {
    Kernel k = std::move(to_);
    k.kind = from_.kind;
    k.site = from_.site;
    return k;
}

ValueId StepBuilder::add(ValueId a, ValueId b) { return to_.op(Op::Add, to_.at(a).type, {a, b}); }

ValueId StepBuilder::mul(ValueId a, ValueId b) {
    Type ta = to_.at(a).type, tb = to_.at(b).type;
    if (ta.width < tb.width) a = to_.op(Op::Splat, tb, {a});
    if (tb.width < ta.width) b = to_.op(Op::Splat, ta, {b});
    return to_.op(Op::Mul, ta.width < tb.width ? tb : ta, {a, b});
}

}  // namespace psys::opt
