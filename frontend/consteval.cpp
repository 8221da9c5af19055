#include "frontend/consteval.h"

#include <cmath>

#include "frontend/builtins.h"

namespace psys {
namespace {

using namespace ast;
using Value = std::optional<ConstValue>;

ConstValue scalar(double x) { return {Type::scalar(), {x, 0, 0, 0}}; }
ConstValue boolean(bool b) { return {Type::boolean(), {b ? 1.0 : 0.0, 0, 0, 0}}; }

// Broadcast a float to `width` components.
double component(const ConstValue& c, int i) { return c.type.width() == 1 ? c.v[0] : c.v[static_cast<size_t>(i)]; }

template <typename F>
Value zipWith(const ConstValue& a, const ConstValue& b, F f) {
    int w = std::max(a.type.width(), b.type.width());
    ConstValue out{Type::vec(w), {}};
    for (int i = 0; i < w; ++i) out.v[static_cast<size_t>(i)] = f(component(a, i), component(b, i));
    return out;
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
    auto unary = [&](double (*f)(double)) -> Value {
        ConstValue out = args[0];
        for (int i = 0; i < out.type.width(); ++i) out.v[static_cast<size_t>(i)] = f(out.v[static_cast<size_t>(i)]);
        return out;
    };
    std::string_view n = fn.name;
    if (n == "sin") return unary([](double x) { return std::sin(x); });
    if (n == "cos") return unary([](double x) { return std::cos(x); });
    if (n == "sqrt") return unary([](double x) { return std::sqrt(x); });
    if (n == "abs") return unary([](double x) { return std::fabs(x); });
    if (n == "exp") return unary([](double x) { return std::exp(x); });
    if (n == "floor") return unary([](double x) { return std::floor(x); });
    if (n == "radians") return unary([](double x) { return x * M_PI / 180.0; });
    if (n == "min") return zipWith(args[0], args[1], [](double a, double b) { return std::min(a, b); });
    if (n == "max") return zipWith(args[0], args[1], [](double a, double b) { return std::max(a, b); });
    if (n == "pow") return zipWith(args[0], args[1], [](double a, double b) { return std::pow(a, b); });
    return std::nullopt;
}

}  // namespace

std::optional<ConstValue> evaluateConstant(const Expr& expr) {
    if (expr.type.isVague() || expr.type.isTuple()) return std::nullopt;
    switch (expr.kind) {
        case ExprKind::Number: return scalar(static_cast<const NumberExpr&>(expr).value);
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
            if (u.op == UnaryOp::Neg)
                for (auto& x : v->v) x = -x;
            return v;
        }
        case ExprKind::Binary: {
            auto& b = static_cast<const BinaryExpr&>(expr);
            Value l = evaluateConstant(*b.lhs), r = evaluateConstant(*b.rhs);
            if (!l || !r) return std::nullopt;
            switch (b.op) {
                case BinaryOp::Add: return zipWith(*l, *r, [](double a, double c) { return a + c; });
                case BinaryOp::Sub: return zipWith(*l, *r, [](double a, double c) { return a - c; });
                case BinaryOp::Mul: return zipWith(*l, *r, [](double a, double c) { return a * c; });
                case BinaryOp::Div: return zipWith(*l, *r, [](double a, double c) { return a / c; });
                case BinaryOp::Mod:
                    return zipWith(*l, *r, [](double a, double c) { return a - c * std::floor(a / c); });
                case BinaryOp::Lt: return boolean(l->v[0] < r->v[0]);
                case BinaryOp::Le: return boolean(l->v[0] <= r->v[0]);
                case BinaryOp::Gt: return boolean(l->v[0] > r->v[0]);
                case BinaryOp::Ge: return boolean(l->v[0] >= r->v[0]);
                case BinaryOp::Eq: return boolean(l->v == r->v);
                case BinaryOp::Ne: return boolean(l->v != r->v);
                case BinaryOp::And: return boolean(l->isTrue() && r->isTrue());
                case BinaryOp::Or: return boolean(l->isTrue() || r->isTrue());
            }
            return std::nullopt;
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

}  // namespace psys
