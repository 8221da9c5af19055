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

#include "frontend/checker.h"
#include "frontend/equation_graph.h"

namespace psys::detail {

using namespace ast;

void Checker::checkAlgebraicLoops(const ObjectDecl& object) {
    EquationGraph graph = buildEquationGraph(object);
    const auto& equations = graph.equations;
    // Only references used in the same update can form a loop.
    std::vector<std::vector<EquationUse>> uses(equations.size());
    for (size_t i = 0; i < equations.size(); ++i)
        for (const EquationUse& u : graph.uses[i])
            if (!u.delayed) uses[i].push_back(u);
    auto components = stronglyConnectedComponents(equations.size(), [&](size_t v) {
        std::vector<size_t> next;
        for (const EquationUse& u : uses[v]) next.push_back(u.target);
        return next;
    });

    for (auto& component : components) {
        std::set<size_t> members(component.begin(), component.end());
        size_t start = *members.begin();  // the first equation in source order
        bool selfLoop = std::any_of(uses[start].begin(), uses[start].end(),
                                    [&](const EquationUse& u) { return u.target == start; });
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
                for (const EquationUse& u : uses[v]) {
                    size_t w = u.target;
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
