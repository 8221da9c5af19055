#include "frontend/equation_graph.h"

#include <algorithm>
#include <map>

#include "frontend/builtins.h"

namespace psys {
namespace {

using namespace ast;

void collect(const Expr& e, const ObjectDecl& object, const std::map<const Equation*, size_t>& index, bool delayed,
             std::vector<EquationUse>& out) {
    auto recurse = [&](const ExprPtr& child, bool d) { collect(*child, object, index, d, out); };
    switch (e.kind) {
        case ExprKind::Name: {
            auto& n = static_cast<const NameExpr&>(e);
            if (n.ref.kind == Ref::Kind::Equation && n.ref.object == &object)
                out.push_back({index.at(n.ref.equation), delayed, n.range});
            return;
        }
        case ExprKind::Call: {
            auto& c = static_cast<const CallExpr&>(e);
            bool delays = false;
            if (c.builtin >= 0) {
                const BuiltinFunction& fn = builtinFunction(c.builtin);
                delays = fn.rule == BuiltinRule::Prev || fn.name == "integrate";
            }
            delays |= c.neighbours != nullptr;  // a fold reads what the last step left
            // (its term's names are exports of the last update: no use in this one)
            for (auto& a : c.args) recurse(a, delayed || delays);
            return;
        }
        case ExprKind::FollowedBy: {
            auto& f = static_cast<const FollowedByExpr&>(e);
            recurse(f.init, delayed);
            recurse(f.next, true);
            return;
        }
        case ExprKind::Member: {
            auto& m = static_cast<const MemberExpr&>(e);
            if (!m.parent) recurse(m.base, delayed);
            return;
        }
        case ExprKind::Unary: recurse(static_cast<const UnaryExpr&>(e).operand, delayed); return;
        case ExprKind::Binary:
            recurse(static_cast<const BinaryExpr&>(e).lhs, delayed);
            recurse(static_cast<const BinaryExpr&>(e).rhs, delayed);
            return;
        case ExprKind::Conditional: {
            auto& c = static_cast<const ConditionalExpr&>(e);
            recurse(c.cond, delayed);
            recurse(c.thenExpr, delayed);
            recurse(c.elseExpr, delayed);
            return;
        }
        case ExprKind::Tuple:
            for (auto& el : static_cast<const TupleExpr&>(e).elements) recurse(el, delayed);
            return;
        case ExprKind::Number: case ExprKind::Bool: return;
    }
}

}  // namespace

EquationGraph buildEquationGraph(const ObjectDecl& object) {
    EquationGraph g;
    std::map<const Equation*, size_t> index;
    for (auto& eq : object.equations) {
        index[eq.get()] = g.equations.size();
        g.equations.push_back(eq.get());
    }
    g.uses.resize(g.equations.size());
    for (size_t i = 0; i < g.equations.size(); ++i) collect(*g.equations[i]->value, object, index, false, g.uses[i]);
    return g;
}

std::vector<std::vector<size_t>> stronglyConnectedComponents(
    size_t vertices, const std::function<std::vector<size_t>(size_t)>& successors) {
    constexpr size_t kUnvisited = static_cast<size_t>(-1);
    std::vector<size_t> order(vertices, kUnvisited), low(vertices, 0), stack;
    std::vector<bool> onStack(vertices, false);
    std::vector<std::vector<size_t>> components;
    size_t counter = 0;
    std::function<void(size_t)> visit = [&](size_t v) {
        order[v] = low[v] = counter++;
        stack.push_back(v);
        onStack[v] = true;
        for (size_t w : successors(v)) {
            if (order[w] == kUnvisited) {
                visit(w);
                low[v] = std::min(low[v], low[w]);
            } else if (onStack[w]) {
                low[v] = std::min(low[v], order[w]);
            }
        }
        if (low[v] != order[v]) return;
        std::vector<size_t> component;
        size_t w;
        do {
            w = stack.back();
            stack.pop_back();
            onStack[w] = false;
            component.push_back(w);
        } while (w != v);
        std::sort(component.begin(), component.end());
        components.push_back(std::move(component));
    };
    for (size_t v = 0; v < vertices; ++v)
        if (order[v] == kUnvisited) visit(v);
    return components;
}

}  // namespace psys
