// The equations of an object as a graph, shared by the algebraic-loop check and by
// lowering's evaluation order, so both agree on what a cycle is.
//
// An edge goes from an equation to every equation of the same object its value refers
// to. It is *delayed* when the reference sits inside `integrate(…)`, `prev(…)` or the
// `next` side of `init -> next`: there a cycle may close (thesis §3.1.5). Live reads of an
// enclosing object (`rocket.pos`) are not edges: they never form a cycle.
#pragma once

#include <functional>
#include <vector>

#include "frontend/ast.h"

namespace psys {

struct EquationUse {
    size_t target;     // index into EquationGraph::equations
    bool delayed;
    SourceRange at;    // the reference
};

struct EquationGraph {
    std::vector<const ast::Equation*> equations;  // in source order
    std::vector<std::vector<EquationUse>> uses;   // per equation, in source order
};

EquationGraph buildEquationGraph(const ast::ObjectDecl& object);

// Strongly connected components (Tarjan), each listed after every component it reaches:
// for a graph of "uses" edges, an order in which everything used comes first. Vertices
// are visited from 0 upwards, so the order is deterministic.
std::vector<std::vector<size_t>> stronglyConnectedComponents(
    size_t vertices, const std::function<std::vector<size_t>(size_t)>& successors);

}  // namespace psys
