#include "frontend/consteval.h"

#include <cmath>

#include <fmt/format.h>

#include "core/lanes.h"
#include "frontend/builtins.h"

namespace psys {
namespace {

using namespace ast;
using Value = std::optional<ConstValue>;
using core::Op;

ConstValue scalar(float x) { return {Type::scalar(), {x, 0, 0, 0}}; }
ConstValue boolean(bool b) { return {Type::boolean(), {b ? 1.0f : 0.0f, 0, 0, 0}}; }

// Broadcast a float to `width` components.
float component(const ConstValue& c, int i) { return c.type.width() == 1 ? c.v[0] : c.v[static_cast<size_t>(i)]; }

// A binary componentwise op, a float broadcasting to the other's width.
ConstValue binary(Op op, const ConstValue& a, const ConstValue& b) {
    int w = std::max(a.type.width(), b.type.width());
    ConstValue out{w == 1 ? Type::scalar() : Type::vec(w), {}};
    for (int i = 0; i < w; ++i) out.v[static_cast<size_t>(i)] = core::lane(op, component(a, i), component(b, i));
    return out;
}

ConstValue unary(Op op, ConstValue x) {
    for (int i = 0; i < x.type.width(); ++i) x.v[static_cast<size_t>(i)] = core::lane(op, x.v[static_cast<size_t>(i)]);
    return x;
}

Value evalCall(const CallExpr& call) {
    if (call.builtin < 0) return std::nullopt;  // user functions are not folded here
    std::vector<ConstValue> args;
    for (auto& a : call.args) {
        Value v = evaluateConstant(*a);
        if (!v) return std::nullopt;
        args.push_back(*v);
    }
    const BuiltinFunction& fn = builtinFunction(call.builtin);
    if (fn.rule == BuiltinRule::Construct) {
        ConstValue out{Type::vec(fn.width), {}};
        if (args.size() == 1 && args[0].type.width() == 1) {
            for (int i = 0; i < fn.width; ++i) out.v[static_cast<size_t>(i)] = args[0].v[0];
            return out;
        }
        size_t n = 0;
        for (auto& a : args)
            for (int i = 0; i < a.type.width() && n < 4; ++i) out.v[n++] = a.v[static_cast<size_t>(i)];
        return out;
    }
    if (fn.op && core::isComponentwise(*fn.op)) {
        if (core::opInfo(*fn.op).arity == 1) return unary(*fn.op, args[0]);
        return binary(*fn.op, args[0], args[1]);
    }
    // The two that lowering writes as a multiplication by a constant.
    if (fn.name == "radians") return binary(Op::Mul, args[0], scalar(core::kRadiansPerDegree));
    if (fn.name == "degrees") return binary(Op::Mul, args[0], scalar(core::kDegreesPerRadian));
    return std::nullopt;
}

Op binaryOp(BinaryOp op) {
    switch (op) {
        case BinaryOp::Add: return Op::Add;
        case BinaryOp::Sub: return Op::Sub;
        case BinaryOp::Mul: return Op::Mul;
        case BinaryOp::Div: return Op::Div;
        case BinaryOp::Mod: return Op::Mod;
        case BinaryOp::Lt: return Op::Lt;
        case BinaryOp::Le: return Op::Le;
        case BinaryOp::Gt: return Op::Gt;
        case BinaryOp::Ge: return Op::Ge;
        case BinaryOp::Eq: return Op::Eq;
        case BinaryOp::Ne: return Op::Ne;
        case BinaryOp::And: return Op::And;
        case BinaryOp::Or: return Op::Or;
    }
    return Op::Add;
}

}  // namespace

std::optional<ConstValue> evaluateConstant(const Expr& expr) {
    if (expr.type.isVague() || expr.type.isTuple()) return std::nullopt;
    switch (expr.kind) {
        case ExprKind::Number: return scalar(static_cast<float>(static_cast<const NumberExpr&>(expr).value));
        case ExprKind::Bool: return boolean(static_cast<const BoolExpr&>(expr).value);
        case ExprKind::Name: {
            auto& name = static_cast<const NameExpr&>(expr);
            if (name.ref.kind == Ref::Kind::Const && name.ref.constant->value)
                return evaluateConstant(*name.ref.constant->value);
            if (name.ref.kind == Ref::Kind::BuiltinConst) {
                const BuiltinConstant& c = builtinConstants()[static_cast<size_t>(name.ref.index)];
                ConstValue out{c.type, {}};
                for (int i = 0; i < 4; ++i) out.v[static_cast<size_t>(i)] = c.value[i];
                return out;
            }
            return std::nullopt;
        }
        case ExprKind::Unary: {
            auto& u = static_cast<const UnaryExpr&>(expr);
            Value v = evaluateConstant(*u.operand);
            if (!v) return std::nullopt;
            if (u.op == UnaryOp::Not) return boolean(!v->isTrue());
            if (u.op == UnaryOp::Neg) return unary(Op::Neg, *v);
            return v;
        }
        case ExprKind::Binary: {
            auto& b = static_cast<const BinaryExpr&>(expr);
            Value l = evaluateConstant(*b.lhs), r = evaluateConstant(*b.rhs);
            if (!l || !r) return std::nullopt;
            Op op = binaryOp(b.op);
            switch (op) {
                case Op::Lt: case Op::Le: case Op::Gt: case Op::Ge: return boolean(core::compare(op, l->v[0], r->v[0]));
                case Op::Eq: return boolean(l->v == r->v);
                case Op::Ne: return boolean(l->v != r->v);
                case Op::And: return boolean(l->isTrue() && r->isTrue());
                case Op::Or: return boolean(l->isTrue() || r->isTrue());
                default: return binary(op, *l, *r);
            }
        }
        case ExprKind::Conditional: {
            auto& c = static_cast<const ConditionalExpr&>(expr);
            Value cond = evaluateConstant(*c.cond);
            if (!cond) return std::nullopt;
            return evaluateConstant(cond->isTrue() ? *c.thenExpr : *c.elseExpr);
        }
        case ExprKind::Member: {
            auto& m = static_cast<const MemberExpr&>(expr);
            if (m.swizzle.empty()) return std::nullopt;
            Value base = evaluateConstant(*m.base);
            if (!base) return std::nullopt;
            ConstValue out{expr.type, {}};
            for (size_t i = 0; i < m.swizzle.size(); ++i) out.v[i] = base->v[static_cast<size_t>(m.swizzle[i])];
            return out;
        }
        case ExprKind::Call: return evalCall(static_cast<const CallExpr&>(expr));
        default: return std::nullopt;
    }
}

std::string numberText(double v) { return std::isnan(v) ? "NaN" : fmt::format("{}", v); }

}  // namespace psys
