// Lowering expressions, and the order an object's equations are evaluated in (see the
// rule at the top of lower.cpp).
#include <optional>

#include "core/fold.h"
#include "frontend/builtins.h"
#include "frontend/equation_graph.h"
#include "lower/object_lowering.h"

namespace psys::lower::detail {

// ---------------------------------------------------------------- evaluation order

std::vector<const Equation*> ObjectLowering::evaluationOrder() {
    EquationGraph graph = buildEquationGraph(*decl_);
    // Components over every reference, each after those it reads: evaluation order.
    auto components = stronglyConnectedComponents(graph.equations.size(), [&](size_t v) {
        std::vector<size_t> next;
        for (const EquationUse& u : graph.uses[v]) next.push_back(u.target);
        return next;
    });
    std::vector<const Equation*> result;
    for (const auto& members : components) {
        // Inside a component: what an equation reads in the same update first. Where that
        // leaves a choice, an equation whose every reference in the component — inside
        // `integrate` too — is already computed, so each cycle is cut once, by the first
        // equation placed (the semi-implicit step on `pos → vel → acc → pos`: one stale
        // read, not two); else source order (members are sorted).
        std::set<size_t> component(members.begin(), members.end()), done;
        auto readsDone = [&](size_t c, bool delayedToo) {
            for (const EquationUse& u : graph.uses[c])
                if ((delayedToo || !u.delayed) && u.target != c && component.count(u.target) && !done.count(u.target))
                    return false;
            return true;
        };
        while (done.size() < component.size()) {
            std::optional<size_t> pick;
            for (bool delayedToo : {true, false}) {
                for (size_t c : members)
                    if (!done.count(c) && readsDone(c, delayedToo)) {
                        pick = c;
                        break;
                    }
                if (pick) break;
            }
            if (!pick)  // an algebraic loop (the front end reported it): keep source order
                for (size_t c : members)
                    if (!done.count(c)) {
                        pick = c;
                        break;
                    }
            done.insert(*pick);
            result.push_back(graph.equations[*pick]);
        }
    }
    return result;
}

// ---------------------------------------------------------------- expressions

ValueId ObjectLowering::broadcastTo(ValueId v, Type t) {
    Type from = k_.at(v).type;
    if (from == t || !t.isVector() || from.width != 1) return v;
    return k_.op(Op::Splat, t, {v});
}

ValueId ObjectLowering::arith(Op op, ValueId a, ValueId b) {
    Type ta = k_.at(a).type, tb = k_.at(b).type;
    Type t = ta.width >= tb.width ? ta : tb;
    return k_.op(op, t, {broadcastTo(a, t), broadcastTo(b, t)});
}

Values ObjectLowering::lowerName(const NameExpr& n) {
    const Ref& r = n.ref;
    Type t = irType(n.type);
    if (pair_ && (r.kind == Ref::Kind::Param || r.kind == Ref::Kind::Equation)) return {neighbourRead(false, n.name, t)};
    switch (r.kind) {
        case Ref::Kind::Param: {
            if (trigger_) return {input(Op::TriggerParam, t, r.index)};
            return {input(Op::Param, t, r.index)};
        }
        case Ref::Kind::TriggerParam: return {input(Op::TriggerParam, t, r.index)};
        case Ref::Kind::Equation: {
            if (auto it = values_.find(r.equation); it != values_.end())
                return {it->second.at(static_cast<size_t>(r.index))};
            // Not evaluated yet: this reference closes a cycle.
            ValueId recur = temporal(Op::Recur, t, {0});
            k_.mutableAt(recur).name = r.equation->names.at(static_cast<size_t>(r.index));
            pendingRecurs_.push_back({recur, {r.equation, static_cast<size_t>(r.index)}});
            return {recur};
        }
        case Ref::Kind::Const: {  // the checker's value, where it could compute one
            const auto& v = r.constant->evaluated;
            if (!v) return lower(*r.constant->value);
            if (t.isBool()) return {k_.boolean(v->isTrue())};
            return {k_.constant(t, t.width == 1 ? std::array<float, 4>{v->v[0], 0, 0, 0} : v->v)};
        }
        case Ref::Kind::Extern: {
            int index = module_.externIndex(r.externVar->name);
            // An instanced program's externs are each instance's (core/instances.h): read
            // from its record, but in a fold's term, which the checker keeps from them.
            if (module_.instanced() && !pair_)
                return {k_.add(Inst::make(Op::Instance, t, {instance()}, core::kInstanceOwnValues + index,
                                          static_cast<int>(module_.externs.size())))};
            return {input(Op::Extern, t, index)};
        }
        case Ref::Kind::FnParam: return frames_.back().params.at(static_cast<size_t>(r.index));
        case Ref::Kind::Let: return frames_.back().lets.at(r.let);
        case Ref::Kind::Age: return {input(Op::Age, Type::f32())};
        case Ref::Kind::Time: return {input(Op::Time, Type::f32())};
        case Ref::Kind::Dt: return {input(Op::Dt, Type::f32())};
        case Ref::Kind::BuiltinConst: {
            const BuiltinConstant& c = builtinConstants()[static_cast<size_t>(r.index)];
            return {k_.constant(t, {c.value[0], c.value[1], c.value[2], c.value[3]})};
        }
        default: return {k_.scalar(0)};
    }
}

ValueId ObjectLowering::parentRead(const MemberExpr& m) {
    Type t = irType(m.type);
    if (m.parentRef.kind == Ref::Kind::Alive) return input(Op::ParentAlive, Type::boolean(), 0, m.parentDepth);
    if (m.parentRef.kind == Ref::Kind::Age) return input(Op::ParentAge, Type::f32(), 0, m.parentDepth);
    std::string member = m.member;
    auto& reads = object_->parentReads;
    for (size_t i = 0; i < reads.size(); ++i)
        if (reads[i].depth == m.parentDepth && reads[i].member == member)
            return input(Op::ParentRead, t, static_cast<int>(i));
    reads.push_back({m.parentDepth, member, t});
    return input(Op::ParentRead, t, static_cast<int>(reads.size() - 1));
}

ValueId ObjectLowering::neighbourRead(bool other, const std::string& member, Type t) {
    auto& reads = object_->neighbourReads;
    for (size_t i = 0; i < reads.size(); ++i)
        if (reads[i].other == other && reads[i].member == member) return input(Op::NeighbourRead, t, static_cast<int>(i));
    reads.push_back({other, member, t});
    return input(Op::NeighbourRead, t, static_cast<int>(reads.size() - 1));
}

// `near_sum(T, r, term)`: a fold of the object's group for (T, r), its term a yield of the
// group's pair kernel, its value a column the run-time fills before the update.
ValueId ObjectLowering::lowerNear(const CallExpr& c) {
    core::Reduce reduce = *core::neighbourFold(c.callee);
    std::string target = qualify(c.neighbours);
    auto& groups = object_->neighbours;
    int group = 0;
    while (static_cast<size_t>(group) < groups.size() &&
           (groups[static_cast<size_t>(group)].target != target || groups[static_cast<size_t>(group)].radius != c.radius))
        ++group;
    if (static_cast<size_t>(group) == groups.size()) {
        groups.push_back({target, c.radius});
        Kernel pair;
        pair.kind = KernelKind::Pair;
        pair.site = group;
        object_->kernels.push_back(std::move(pair));
    }
    Kernel& pair = *object_->kernel(KernelKind::Pair, group);
    LocScope at(pair, k_.loc());
    int sites = 0;
    ObjectLowering term(module_, locate_, pair, object_, decl_, nullptr, sites);
    term.qualify = qualify;
    term.pair_ = true;
    Type t = irType(c.type);
    ValueId value = core::reduceInfo(reduce).term ? term.lowerOne(*c.args[2]) : pair.scalar(1);
    int fold = static_cast<int>(object_->folds.size());
    object_->folds.push_back({group, reduce, t});
    pair.yields.push_back({YieldKind::Fold, fold, 0, value});
    return input(Op::Fold, t, fold);
}

ValueId ObjectLowering::instanceMember(int member) {
    const InstanceMember& m = instanceMembers()[static_cast<size_t>(member)];
    ValueId record = instanceRecord(m.record);
    if (m.width == 1) return extract(record, m.first);
    std::vector<uint8_t> lanes;
    for (int l = 0; l < m.width; ++l) lanes.push_back(static_cast<uint8_t>(m.first + l));
    return shuffle(record, lanes);
}

Values ObjectLowering::lower(const Expr& e) {
    LocScope at(k_, locate_(e.range));
    switch (e.kind) {
        case ExprKind::Number: return {k_.scalar(static_cast<float>(static_cast<const NumberExpr&>(e).value))};
        case ExprKind::Bool: return {k_.boolean(static_cast<const BoolExpr&>(e).value)};
        case ExprKind::Name: return lowerName(static_cast<const NameExpr&>(e));
        case ExprKind::Call: return lowerCall(static_cast<const CallExpr&>(e));
        case ExprKind::Member: {
            auto& m = static_cast<const MemberExpr&>(e);
            if (m.neighbour) return {neighbourRead(true, m.member, irType(m.type))};
            if (m.instance >= 0) return {instanceMember(m.instance)};
            if (m.parent) return {parentRead(m)};
            ValueId base = lowerOne(*m.base);
            if (m.swizzle.size() == 1) return {extract(base, m.swizzle[0])};
            std::vector<uint8_t> lanes(m.swizzle.begin(), m.swizzle.end());
            return {shuffle(base, lanes)};
        }
        case ExprKind::Unary: {
            auto& u = static_cast<const UnaryExpr&>(e);
            ValueId v = lowerOne(*u.operand);
            if (u.op == UnaryOp::Plus) return {v};
            if (u.op == UnaryOp::Not) return {k_.op(Op::Not, Type::boolean(), {v})};
            return {k_.op(Op::Neg, k_.at(v).type, {v})};
        }
        case ExprKind::Binary: {
            auto& b = static_cast<const BinaryExpr&>(e);
            ValueId l = lowerOne(*b.lhs), r = lowerOne(*b.rhs);
            switch (b.op) {
                case BinaryOp::Add: return {arith(Op::Add, l, r)};
                case BinaryOp::Sub: return {arith(Op::Sub, l, r)};
                case BinaryOp::Mul: return {arith(Op::Mul, l, r)};
                case BinaryOp::Div: return {arith(Op::Div, l, r)};
                case BinaryOp::Mod: return {arith(Op::Mod, l, r)};
                case BinaryOp::Lt: return {k_.op(Op::Lt, Type::boolean(), {l, r})};
                case BinaryOp::Le: return {k_.op(Op::Le, Type::boolean(), {l, r})};
                case BinaryOp::Gt: return {k_.op(Op::Gt, Type::boolean(), {l, r})};
                case BinaryOp::Ge: return {k_.op(Op::Ge, Type::boolean(), {l, r})};
                case BinaryOp::Eq: return {k_.op(Op::Eq, Type::boolean(), {l, r})};
                case BinaryOp::Ne: return {k_.op(Op::Ne, Type::boolean(), {l, r})};
                case BinaryOp::And: return {k_.op(Op::And, Type::boolean(), {l, r})};
                case BinaryOp::Or: return {k_.op(Op::Or, Type::boolean(), {l, r})};
            }
            return {l};
        }
        case ExprKind::Conditional: {
            auto& c = static_cast<const ConditionalExpr&>(e);
            ValueId cond = lowerOne(*c.cond);
            Values a = lower(*c.thenExpr), b = lower(*c.elseExpr);
            Values out;
            for (size_t i = 0; i < a.size(); ++i) out.push_back(k_.op(Op::Select, k_.at(a[i]).type, {cond, a[i], b[i]}));
            return out;
        }
        case ExprKind::Tuple: {
            Values out;
            for (auto& el : static_cast<const TupleExpr&>(e).elements) out.push_back(lowerOne(*el));
            return out;
        }
        case ExprKind::FollowedBy: {
            auto& f = static_cast<const FollowedByExpr&>(e);
            Values a = lower(*f.init), b = lower(*f.next);
            Values out;
            for (size_t i = 0; i < a.size(); ++i) out.push_back(temporal(Op::FollowedBy, k_.at(a[i]).type, {a[i], b[i]}));
            return out;
        }
    }
    return {k_.scalar(0)};
}


}  // namespace psys::lower::detail
