// Algebraic loops: equations that need their own value in the same update.
//
// Equations may refer to each other in a cycle only when the cycle passes through
// `integrate`, `prev` or the `next` side of `init -> next`: there the value read is the one
// of the previous update (or the initial value), so the cycle becomes state (thesis
// §3.1.5, §4.3.3). Any other cycle has no solution an update could compute, and is
// reported with its path. (`snapshot` and `derive` do not break a cycle: the first needs
// the value at creation, the second the current value.)
#include <algorithm>
#include <functional>

#include <fmt/format.h>

#include "frontend/builtins.h"
#include "frontend/checker.h"

namespace psys::detail {

using namespace ast;

namespace {

struct Use {
    const Equation* target;
    SourceRange at;
};

// The equations of `object` that `expr` reads in the same update.
void collectImmediateUses(const Expr& expr, const ObjectDecl& object, std::vector<Use>& uses) {
    switch (expr.kind) {
        case ExprKind::Name: {
            auto& name = static_cast<const NameExpr&>(expr);
            if (name.ref.kind == Ref::Kind::Equation && name.ref.object == &object)
                uses.push_back({name.ref.equation, name.range});
            return;
        }
        case ExprKind::Call: {
            auto& call = static_cast<const CallExpr&>(expr);
            if (call.builtin >= 0) {
                const BuiltinFunction& fn = builtinFunction(call.builtin);
                bool delays = fn.rule == BuiltinRule::Prev || fn.name == "integrate";
                if (delays) return;
            }
            for (auto& a : call.args) collectImmediateUses(*a, object, uses);
            return;
        }
        case ExprKind::FollowedBy:
            collectImmediateUses(*static_cast<const FollowedByExpr&>(expr).init, object, uses);
            return;
        case ExprKind::Member: {
            auto& m = static_cast<const MemberExpr&>(expr);
            if (!m.parent) collectImmediateUses(*m.base, object, uses);
            return;
        }
        case ExprKind::Unary: collectImmediateUses(*static_cast<const UnaryExpr&>(expr).operand, object, uses); return;
        case ExprKind::Binary: {
            auto& b = static_cast<const BinaryExpr&>(expr);
            collectImmediateUses(*b.lhs, object, uses);
            collectImmediateUses(*b.rhs, object, uses);
            return;
        }
        case ExprKind::Conditional: {
            auto& c = static_cast<const ConditionalExpr&>(expr);
            collectImmediateUses(*c.cond, object, uses);
            collectImmediateUses(*c.thenExpr, object, uses);
            collectImmediateUses(*c.elseExpr, object, uses);
            return;
        }
        case ExprKind::Tuple:
            for (auto& e : static_cast<const TupleExpr&>(expr).elements) collectImmediateUses(*e, object, uses);
            return;
        case ExprKind::Number: case ExprKind::Bool: return;
    }
}

}  // namespace

void Checker::checkAlgebraicLoops(const ObjectDecl& object) {
    const auto& equations = object.equations;
    std::map<const Equation*, size_t> index;
    for (size_t i = 0; i < equations.size(); ++i) index[equations[i].get()] = i;
    std::vector<std::vector<Use>> uses(equations.size());
    for (size_t i = 0; i < equations.size(); ++i) collectImmediateUses(*equations[i]->value, object, uses[i]);

    // Tarjan's strongly connected components.
    size_t counter = 0;
    std::vector<size_t> order(equations.size(), SIZE_MAX), low(equations.size(), 0);
    std::vector<bool> onStack(equations.size(), false);
    std::vector<size_t> stack;
    std::vector<std::vector<size_t>> components;
    std::function<void(size_t)> visit = [&](size_t v) {
        order[v] = low[v] = counter++;
        stack.push_back(v);
        onStack[v] = true;
        for (const Use& u : uses[v]) {
            size_t w = index.at(u.target);
            if (order[w] == SIZE_MAX) {
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
        components.push_back(std::move(component));
    };
    for (size_t v = 0; v < equations.size(); ++v)
        if (order[v] == SIZE_MAX) visit(v);

    for (auto& component : components) {
        std::set<size_t> members(component.begin(), component.end());
        size_t start = *members.begin();  // the first equation in source order
        bool selfLoop = std::any_of(uses[start].begin(), uses[start].end(),
                                    [&](const Use& u) { return index.at(u.target) == start; });
        if (members.size() == 1 && !selfLoop) continue;

        // A shortest way round the loop from `start`, by breadth-first search inside it.
        std::map<size_t, std::pair<size_t, SourceRange>> cameFrom;
        std::vector<size_t> frontier = {start};
        bool closed = false;
        SourceRange closing;
        size_t last = start;
        while (!frontier.empty() && !closed) {
            std::vector<size_t> next;
            for (size_t v : frontier) {
                for (const Use& u : uses[v]) {
                    size_t w = index.at(u.target);
                    if (!members.count(w)) continue;
                    if (w == start) {
                        closed = true;
                        closing = u.at;
                        last = v;
                        break;
                    }
                    if (cameFrom.count(w)) continue;
                    cameFrom[w] = {v, u.at};
                    next.push_back(w);
                }
                if (closed) break;
            }
            frontier = std::move(next);
        }
        std::vector<std::pair<size_t, SourceRange>> steps;  // (equation, where it uses the next)
        steps.push_back({last, closing});
        for (size_t v = last; v != start;) {
            auto [from, at] = cameFrom.at(v);
            steps.push_back({from, at});
            v = from;
        }
        std::reverse(steps.begin(), steps.end());
        auto nameOf = [&](size_t i) { return equations[i]->names.front(); };
        std::string path;
        for (auto& [eq, _] : steps) path += nameOf(eq) + " → ";
        path += nameOf(start);
        Diagnostic& d = diags_.error(
            equations[start]->nameRanges.front(),
            fmt::format("algebraic loop: `{}` needs its own value in the same update ({}); break the cycle with "
                        "`prev`, `integrate` or an initial value `init -> …`", nameOf(start), path));
        for (size_t i = 0; i < steps.size(); ++i) {
            size_t used = i + 1 < steps.size() ? steps[i + 1].first : start;
            d.notes.push_back({steps[i].second, fmt::format("`{}` uses `{}` here", nameOf(steps[i].first), nameOf(used))});
        }
    }
}

}  // namespace psys::detail
