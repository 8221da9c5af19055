// Lowering: the checked AST to IR behaviour kernels.
//
// Each object becomes one behaviour kernel that still says what the program said: the
// temporal constructs (integrate, derive, snapshot, prev, `->`), random draws and parent
// reads are instructions of their own, and opt/ makes them explicit state, keys and
// exports. What lowering decides is the order of evaluation, which is the language's
// semantics for recursive equations (docs/language.md, "Evaluation order"):
//
//   Equations are evaluated so that everything an equation reads in the same update is
//   computed before it; where that leaves a choice, in source order. A reference that
//   must read an equation evaluated later in this order — one that closes a cycle, which
//   the front end allows only through `integrate`, `prev` or the `next` side of `->` — is
//   a `recur` instruction: opt/resolve_cycles makes it the value of the previous update.
//   The operand of `prev` is the exception: it is only needed for the slot's next value,
//   once the update has computed everything, so it is lowered last and reads this
//   update's values.
//
// Functions are inlined; every inlined `rand` gets its own call site. Broadcasts become
// explicit `splat`s and the library functions (mix, clamp, rotate_y, normalize, …) become
// arithmetic, so later passes see every operation.
#include "ir/lower.h"

#include <algorithm>
#include <functional>
#include <map>
#include <set>
#include <tuple>

#include <fmt/format.h>

#include "frontend/builtins.h"
#include "frontend/consteval.h"
#include "frontend/equation_graph.h"

namespace psys::ir {
namespace {

using namespace ast;

Type irType(const psys::Type& t) {
    if (t.isBool()) return Type::boolean();
    return Type::vec(std::max(1, t.width()));
}

// A lowered expression: one value, or several for a tuple.
using Values = std::vector<ValueId>;

struct FnFrame {
    const FnDecl* fn;
    std::vector<Values> params;
    std::map<const LetStmt*, Values> lets;
};

class ObjectLowering {
public:
    ObjectLowering(const Module& module, Kernel& kernel, Object* object, const ObjectDecl* decl,
                   const TriggerDecl* trigger, int& siteCounter)
        : module_(module), k_(kernel), object_(object), decl_(decl), trigger_(trigger), site_(siteCounter) {}

    // The object's equations, in evaluation order.
    void lowerEquations() {
        for (size_t i = 0; i < decl_->params.size(); ++i)
            k_.equations[decl_->params[i].name] = input(Op::Param, irType(decl_->params[i].type.type), static_cast<int>(i));
        std::vector<const Equation*> order = evaluationOrder();
        for (const Equation* eq : order) {
            current_ = eq;
            Values v = lower(*eq->value);
            for (size_t i = 0; i < eq->names.size() && i < v.size(); ++i) {
                name(v[i], eq->names[i]);
                k_.equations[eq->names[i]] = v[i];
            }
            values_[eq] = v;
        }
        current_ = nullptr;
        for (auto& [recur, target] : pendingRecurs_) {
            ValueId value = values_.at(target.first).at(target.second);
            k_.mutableAt(recur).operands = {value};
        }
        flushDeferred();
    }

    // `prev(e)` reads a slot; `e` itself is needed only for the slot's next value, at the
    // end of the update, when every equation has its current value. So `e` is lowered
    // last, and what it reads is this update's value even where it refers forward.
    void flushDeferred() {
        while (!deferred_.empty()) {
            auto [prev, arg, frames] = std::move(deferred_.back());
            deferred_.pop_back();
            auto saved = std::move(frames_);
            frames_ = std::move(frames);
            ValueId v = lowerOne(*arg);
            frames_ = std::move(saved);
            k_.mutableAt(prev).operands = {v};
        }
    }

    Values lower(const Expr& e);
    ValueId lowerOne(const Expr& e) { return lower(e).at(0); }

    // Adds `value` as `kind` under the conditions of the enclosing `when`s.
    ValueId guard(const std::vector<ValueId>& conditions) {
        ValueId all = k_.boolean(true);
        for (ValueId c : conditions) all = k_.op(Op::And, Type::boolean(), {all, c});
        return all;
    }

private:
    void name(ValueId v, const std::string& n) {
        Inst& inst = k_.mutableAt(v);
        if (inst.name.empty() && !isInput(inst.op)) inst.name = n;
    }

    std::vector<const Equation*> evaluationOrder();
    Values lowerName(const NameExpr& n);
    Values lowerCall(const CallExpr& c);
    ValueId broadcastTo(ValueId v, Type t);
    ValueId arith(Op op, ValueId a, ValueId b);
    ValueId scalarConst(float x, Type t) {
        if (t.width == 1) return k_.scalar(x);
        return k_.constant(t, {x, x, x, x});
    }
    ValueId extract(ValueId v, int i) {
        Inst inst;
        inst.op = Op::Extract;
        inst.type = Type::f32();
        inst.operands = {v};
        inst.attr = i;
        return k_.add(std::move(inst));
    }
    ValueId shuffle(ValueId v, std::vector<uint8_t> lanes) {
        Inst inst;
        inst.op = Op::Shuffle;
        inst.type = Type::vec(static_cast<int>(lanes.size()));
        inst.operands = {v};
        inst.lanes = std::move(lanes);
        return k_.add(std::move(inst));
    }
    ValueId temporal(Op op, Type t, std::vector<ValueId> operands) {
        Inst inst;
        inst.op = op;
        inst.type = t;
        inst.operands = std::move(operands);
        inst.attr = site_++;
        if ((op == Op::Rand || op == Op::NRand) && (perChild_ || !decl_)) inst.attr2 = 1;
        return k_.addUnique(std::move(inst));
    }
    ValueId input(Op op, Type t, int attr = 0, int attr2 = 0) {
        Inst inst;
        inst.op = op;
        inst.type = t;
        inst.attr = attr;
        inst.attr2 = attr2;
        return k_.add(std::move(inst));
    }
    ValueId parentRead(const MemberExpr& m);

public:
    // While lowering emit arguments: random draws there are one per created object.
    bool perChild_ = false;

private:

    const Module& module_;
    Kernel& k_;
    Object* object_;
    const ObjectDecl* decl_;
    const TriggerDecl* trigger_;
    int& site_;
    std::map<const Equation*, Values> values_;
    std::vector<std::pair<ValueId, std::pair<const Equation*, size_t>>> pendingRecurs_;
    const Equation* current_ = nullptr;
    std::vector<FnFrame> frames_;
    std::vector<std::tuple<ValueId, const Expr*, std::vector<FnFrame>>> deferred_;
};

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
        // Inside a component: what an equation reads in the same update first, else
        // source order (members are sorted).
        std::set<size_t> component(members.begin(), members.end()), done;
        while (done.size() < component.size()) {
            for (size_t c : members) {
                if (done.count(c)) continue;
                bool ready = true;
                for (const EquationUse& u : graph.uses[c])
                    if (!u.delayed && u.target != c && component.count(u.target) && !done.count(u.target)) ready = false;
                if (!ready) continue;
                done.insert(c);
                result.push_back(graph.equations[c]);
                break;
            }
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
        case Ref::Kind::Const: return lower(*r.constant->value);
        case Ref::Kind::Extern: return {input(Op::Extern, t, module_.externIndex(r.externVar->name))};
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

Values ObjectLowering::lower(const Expr& e) {
    switch (e.kind) {
        case ExprKind::Number: return {k_.scalar(static_cast<float>(static_cast<const NumberExpr&>(e).value))};
        case ExprKind::Bool: return {k_.boolean(static_cast<const BoolExpr&>(e).value)};
        case ExprKind::Name: return lowerName(static_cast<const NameExpr&>(e));
        case ExprKind::Call: return lowerCall(static_cast<const CallExpr&>(e));
        case ExprKind::Member: {
            auto& m = static_cast<const MemberExpr&>(e);
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

Values ObjectLowering::lowerCall(const CallExpr& c) {
    if (c.fn) {
        FnFrame frame{c.fn, {}, {}};
        for (auto& a : c.args) frame.params.push_back(lower(*a));
        frames_.push_back(std::move(frame));
        for (auto& let : c.fn->lets) {
            Values v = lower(*let->value);
            frames_.back().lets[let.get()] = v;
        }
        Values result = lower(*c.fn->body);
        frames_.pop_back();
        return result;
    }
    const BuiltinFunction& fn = builtinFunction(c.builtin);
    Type t = irType(c.type);
    if (fn.rule == BuiltinRule::Prev) {
        ValueId prev = temporal(Op::Prev, t, {0});
        deferred_.push_back({prev, c.args[0].get(), frames_});
        return {prev};
    }
    std::vector<ValueId> a;
    for (auto& arg : c.args) a.push_back(lowerOne(*arg));
    auto b = [&](size_t i) { return broadcastTo(a.at(i), t); };
    auto unary = [&](Op op) { return Values{k_.op(op, t, {b(0)})}; };
    auto binary = [&](Op op) { return Values{k_.op(op, t, {b(0), b(1)})}; };
    auto mix = [&](ValueId x, ValueId y, ValueId s) {  // x + (y - x) * s
        return k_.op(Op::Add, t, {x, k_.op(Op::Mul, t, {k_.op(Op::Sub, t, {y, x}), s})});
    };
    auto clamp = [&](ValueId x, ValueId lo, ValueId hi) {
        return k_.op(Op::Min, t, {k_.op(Op::Max, t, {x, lo}), hi});
    };
    std::string_view n = fn.name;
    switch (fn.rule) {
        case BuiltinRule::Componentwise:
            if (n == "sin") return unary(Op::Sin);
            if (n == "cos") return unary(Op::Cos);
            if (n == "tan") return unary(Op::Tan);
            if (n == "asin") return unary(Op::Asin);
            if (n == "acos") return unary(Op::Acos);
            if (n == "atan") return unary(Op::Atan);
            if (n == "exp") return unary(Op::Exp);
            if (n == "log") return unary(Op::Log);
            if (n == "sqrt") return unary(Op::Sqrt);
            if (n == "abs") return unary(Op::Abs);
            if (n == "sign") return unary(Op::Sign);
            if (n == "floor") return unary(Op::Floor);
            if (n == "ceil") return unary(Op::Ceil);
            if (n == "round") return unary(Op::Round);
            if (n == "fract") return unary(Op::Fract);
            if (n == "atan2") return binary(Op::Atan2);
            if (n == "pow") return binary(Op::Pow);
            if (n == "mod") return binary(Op::Mod);
            if (n == "min") return binary(Op::Min);
            if (n == "max") return binary(Op::Max);
            if (n == "step") return binary(Op::Step);
            if (n == "radians") return {k_.op(Op::Mul, t, {b(0), scalarConst(static_cast<float>(M_PI / 180), t)})};
            if (n == "degrees") return {k_.op(Op::Mul, t, {b(0), scalarConst(static_cast<float>(180 / M_PI), t)})};
            if (n == "saturate") return {clamp(b(0), scalarConst(0, t), scalarConst(1, t))};
            if (n == "clamp")
                return {clamp(b(0), a.size() > 1 ? b(1) : scalarConst(0, t), a.size() > 2 ? b(2) : scalarConst(1, t))};
            if (n == "mix" || n == "lerp") return {mix(b(0), b(1), b(2))};
            if (n == "smoothstep") {  // s = clamp((x - e0) / (e1 - e0)); s * s * (3 - 2 * s)
                ValueId s = clamp(k_.op(Op::Div, t, {k_.op(Op::Sub, t, {b(2), b(0)}), k_.op(Op::Sub, t, {b(1), b(0)})}),
                                  scalarConst(0, t), scalarConst(1, t));
                ValueId poly = k_.op(Op::Sub, t, {scalarConst(3, t), k_.op(Op::Mul, t, {scalarConst(2, t), s})});
                return {k_.op(Op::Mul, t, {k_.op(Op::Mul, t, {s, s}), poly})};
            }
            break;
        case BuiltinRule::ToScalar: {
            if (n == "dot") return {k_.op(Op::Dot, Type::f32(), {a[0], a[1]})};
            ValueId v = n == "distance" ? k_.op(Op::Sub, k_.at(a[0]).type, {a[0], a[1]}) : a[0];
            if (!k_.at(v).type.isVector()) return {k_.op(Op::Abs, Type::f32(), {v})};
            return {k_.op(Op::Sqrt, Type::f32(), {k_.op(Op::Dot, Type::f32(), {v, v})})};
        }
        case BuiltinRule::SameVector: {
            if (n == "normalize") {  // v * (1 / sqrt(dot(v, v)))
                ValueId inv = k_.op(Op::Div, Type::f32(),
                                    {k_.scalar(1), k_.op(Op::Sqrt, Type::f32(), {k_.op(Op::Dot, Type::f32(), {a[0], a[0]})})});
                return {k_.op(Op::Mul, t, {a[0], broadcastTo(inv, t)})};
            }
            // reflect(v, n) = v - 2 * dot(n, v) * n
            ValueId d = k_.op(Op::Mul, Type::f32(), {k_.scalar(2), k_.op(Op::Dot, Type::f32(), {a[1], a[0]})});
            return {k_.op(Op::Sub, t, {a[0], k_.op(Op::Mul, t, {broadcastTo(d, t), a[1]})})};
        }
        case BuiltinRule::Cross: {  // a.yzx * b.zxy - a.zxy * b.yzx
            ValueId l = k_.op(Op::Mul, t, {shuffle(a[0], {1, 2, 0}), shuffle(a[1], {2, 0, 1})});
            ValueId r = k_.op(Op::Mul, t, {shuffle(a[0], {2, 0, 1}), shuffle(a[1], {1, 2, 0})});
            return {k_.op(Op::Sub, t, {l, r})};
        }
        case BuiltinRule::Rotate: {
            ValueId c = k_.op(Op::Cos, Type::f32(), {a[1]}), s = k_.op(Op::Sin, Type::f32(), {a[1]});
            ValueId x = extract(a[0], 0), y = extract(a[0], 1), z = extract(a[0], 2);
            auto f = [&](Op op, ValueId p, ValueId q) { return k_.op(op, Type::f32(), {p, q}); };
            auto rot = [&](ValueId u, ValueId w) {  // (u cos - w sin, u sin + w cos)
                return std::pair{f(Op::Sub, f(Op::Mul, u, c), f(Op::Mul, w, s)),
                                 f(Op::Add, f(Op::Mul, u, s), f(Op::Mul, w, c))};
            };
            if (n == "rotate_x") {
                auto [ny, nz] = rot(y, z);
                return {k_.op(Op::Compose, t, {x, ny, nz})};
            }
            if (n == "rotate_y") {  // right-handed about +y: z towards x
                auto [nz, nx] = rot(z, x);
                return {k_.op(Op::Compose, t, {nx, y, nz})};
            }
            auto [nx, ny] = rot(x, y);
            return {k_.op(Op::Compose, t, {nx, ny, z})};
        }
        case BuiltinRule::Construct:
            if (a.size() == 1 && k_.at(a[0]).type.width == 1) return {k_.op(Op::Splat, t, {a[0]})};
            return {k_.op(Op::Compose, t, a)};
        case BuiltinRule::Integrate:
            return {temporal(n == "integrate" ? Op::Integrate : Op::Derive, t, {a[0]})};
        case BuiltinRule::Snapshot: return {temporal(Op::Snapshot, t, {a[0]})};
        case BuiltinRule::Prev: break;  // handled above
        case BuiltinRule::Random:
            return {temporal(n.substr(0, 1) == "n" ? Op::NRand : Op::Rand, t, {})};
    }
    return {k_.scalar(0)};
}

// ---------------------------------------------------------------- commands

struct CommandLowering {
    ObjectLowering& lowering;
    Kernel& k;
    std::vector<EmitSite>& emits;
    const ast::Program& program;
    std::function<std::string(const ObjectDecl*)> qualified;

    void run(const std::vector<CommandPtr>& commands, std::vector<ValueId> conditions, ValueId& kill) {
        for (auto& cmd : commands) {
            switch (cmd->kind) {
                case CommandKind::Point: {
                    k.yields.push_back({YieldKind::Position, 0, 0, lowering.lowerOne(*cmd->args[0])});
                    k.yields.push_back({YieldKind::Color, 0, 0, lowering.lowerOne(*cmd->args[1])});
                    k.yields.push_back({YieldKind::Size, 0, 0, lowering.lowerOne(*cmd->args[2])});
                    k.yields.push_back({YieldKind::Visible, 0, 0, lowering.guard(conditions)});
                    break;
                }
                case CommandKind::Kill: {
                    ValueId c = cmd->cond ? lowering.lowerOne(*cmd->cond) : k.boolean(true);
                    ValueId guarded = k.op(Op::And, Type::boolean(), {lowering.guard(conditions), c});
                    kill = k.op(Op::Or, Type::boolean(), {kill, guarded});
                    break;
                }
                case CommandKind::Emit: {
                    int site = static_cast<int>(emits.size());
                    emits.push_back({qualified(cmd->targetDecl), cmd->rate != nullptr});
                    ValueId on = lowering.guard(conditions);
                    ValueId zero = k.scalar(0);
                    ValueId count = cmd->count ? lowering.lowerOne(*cmd->count) : k.scalar(1);
                    if (cmd->rate) {
                        ValueId rate = lowering.lowerOne(*cmd->rate);
                        k.yields.push_back({YieldKind::EmitRate, site, 0, k.op(Op::Select, Type::f32(), {on, rate, zero})});
                        k.yields.push_back({YieldKind::EmitCount, site, 0, count});
                    } else {
                        k.yields.push_back({YieldKind::EmitCount, site, 0, k.op(Op::Select, Type::f32(), {on, count, zero})});
                    }
                    lowering.perChild_ = true;
                    for (size_t i = 0; i < cmd->args.size(); ++i)
                        k.yields.push_back({YieldKind::EmitArg, site, static_cast<int>(i), lowering.lowerOne(*cmd->args[i])});
                    lowering.perChild_ = false;
                    break;
                }
                case CommandKind::When: {
                    auto inner = conditions;
                    inner.push_back(lowering.lowerOne(*cmd->cond));
                    run(cmd->body, inner, kill);
                    break;
                }
            }
        }
    }
};

std::array<float, 4> constantValue(const Expr* e, Type t) {
    std::array<float, 4> out{};
    if (!e) return out;
    auto v = evaluateConstant(*e);
    if (!v) return out;
    for (int i = 0; i < 4; ++i) out[static_cast<size_t>(i)] = static_cast<float>(v->type.width() == 1 ? v->v[0] : v->v[static_cast<size_t>(i)]);
    if (t.isBool()) out = {v->isTrue() ? 1.0f : 0.0f, 0, 0, 0};
    return out;
}

}  // namespace

Module lower(const ast::Program& program) {
    Module m;
    // Externs first: kernels refer to them by index.
    for (auto& module : program.modules)
        for (auto& d : module->decls)
            if (d->kind == DeclKind::Extern) {
                auto& e = static_cast<const ExternDecl&>(*d);
                Extern x{e.name, irType(e.type.type), constantValue(e.defaultValue.get(), irType(e.type.type)), {}, {}};
                if (e.rangeLow) {
                    x.low = constantValue(e.rangeLow.get(), x.type);
                    x.high = constantValue(e.rangeHigh.get(), x.type);
                }
                m.externs.push_back(x);
            }

    // Objects, parents before children; nested objects get qualified names.
    std::map<const ObjectDecl*, std::string> names;
    std::function<std::string(const ObjectDecl*)> qualified = [&](const ObjectDecl* o) -> std::string {
        if (!o) return "";
        if (auto it = names.find(o); it != names.end()) return it->second;
        return names[o] = o->parent ? qualified(o->parent) + "." + o->name : o->name;
    };
    std::vector<std::pair<const ObjectDecl*, std::map<std::string, std::string>>> decls;
    std::function<void(const ObjectDecl&, std::map<std::string, std::string>)> collect =
        [&](const ObjectDecl& o, std::map<std::string, std::string> attributes) {
            for (auto& a : o.attributes)
                if (!a.args.empty()) {
                    if (a.args[0]->kind == ExprKind::Name) attributes[a.name] = static_cast<const NameExpr&>(*a.args[0]).name;
                    else if (auto v = evaluateConstant(*a.args[0])) attributes[a.name] = fmt::format("{}", v->v[0]);
                }
            decls.push_back({&o, attributes});
            for (auto& child : o.children) collect(*child, attributes);
        };
    for (auto& module : program.modules) {
        std::map<std::string, std::string> fileAttributes;
        for (auto& d : module->decls)
            if (d->kind == DeclKind::Attribute) {
                auto& a = static_cast<const FileAttributeDecl&>(*d).attribute;
                if (!a.args.empty() && a.args[0]->kind == ExprKind::Name)
                    fileAttributes[a.name] = static_cast<const NameExpr&>(*a.args[0]).name;
                else if (!a.args.empty())
                    if (auto v = evaluateConstant(*a.args[0])) fileAttributes[a.name] = fmt::format("{}", v->v[0]);
            }
        for (auto& d : module->decls)
            if (d->kind == DeclKind::Object) collect(static_cast<const ObjectDecl&>(*d), fileAttributes);
    }
    // Every object exists before any kernel is lowered: emits name their targets.
    for (auto& [decl, attributes] : decls) {
        Object o;
        o.name = qualified(decl);
        o.parent = qualified(decl->parent);
        o.attributes = attributes;
        for (auto& p : decl->params) o.params.push_back({p.name, irType(p.type.type)});
        m.objects.push_back(std::move(o));
    }
    for (size_t i = 0; i < decls.size(); ++i) {
        const ObjectDecl* decl = decls[i].first;
        Object& o = m.objects[i];
        Kernel k;
        k.kind = KernelKind::Behaviour;
        int sites = 0;
        ObjectLowering lowering(m, k, &o, decl, nullptr, sites);
        lowering.lowerEquations();
        ValueId kill = k.boolean(false);
        CommandLowering commands{lowering, k, o.emits, program, qualified};
        commands.run(decl->commands, {}, kill);
        lowering.flushDeferred();
        k.yields.push_back({YieldKind::Kill, 0, 0, kill});
        o.kernels.push_back(std::move(k));
    }

    // Triggers and the start of the system.
    for (auto& module : program.modules)
        for (auto& d : module->decls) {
            if (d->kind == DeclKind::Trigger) {
                auto& t = static_cast<const TriggerDecl&>(*d);
                Trigger trigger;
                trigger.name = t.name;
                for (auto& p : t.params) trigger.params.push_back({p.name, irType(p.type.type)});
                trigger.kernel.kind = KernelKind::Trigger;
                int sites = 0;
                ObjectLowering lowering(m, trigger.kernel, nullptr, nullptr, &t, sites);
                ValueId kill = trigger.kernel.boolean(false);
                CommandLowering commands{lowering, trigger.kernel, trigger.emits, program, qualified};
                commands.run(t.commands, {}, kill);
                m.triggers.push_back(std::move(trigger));
            }
        }
    m.start.name = "start";
    m.start.kernel.kind = KernelKind::Start;
    int startSites = 0;
    ObjectLowering startLowering(m, m.start.kernel, nullptr, nullptr, nullptr, startSites);
    for (auto& module : program.modules)
        for (auto& d : module->decls)
            if (d->kind == DeclKind::Spawn) {
                auto& s = static_cast<const SpawnDecl&>(*d);
                int site = static_cast<int>(m.start.emits.size());
                m.start.emits.push_back({qualified(s.targetDecl), false});
                m.start.kernel.yields.push_back({YieldKind::EmitCount, site, 0, m.start.kernel.scalar(1)});
                for (size_t i = 0; i < s.args.size(); ++i)
                    m.start.kernel.yields.push_back(
                        {YieldKind::EmitArg, site, static_cast<int>(i), startLowering.lowerOne(*s.args[i])});
            }
    return m;
}

}  // namespace psys::ir
