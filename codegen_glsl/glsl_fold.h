// A neighbour group's folds as a GLSL compute shader (gpu/gl_fold.cpp runs it, after
// building the grid on the GPU): one invocation per object of the folding type (in the
// grid's order where it folds over itself: a cell's objects side by side), walking
// the 27 cells around it in the order the run-time's host fold walks them
// (rt/neighbours.cpp) — buckets ascending, rows ascending within one — and combining each
// term as core/fold.h does.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "ir/ir.h"

namespace psys::codegen_glsl {

// Where the shader reads its inputs (gpu/gl_fold.cpp packs them): word k of `Words` — 0
// the folding type's rows, 1 the other's, 2 the buckets' mask, 3 the inverse of a
// cell's width, 4 the radius squared (float bits), 5 whether the two types are one, 6 a
// zero; the externs from kFoldExterns, 4 words each. Each side's columns packed in slots of
// its rows: slot 0 its mask, 1–3 its drawn position, then `self` / `other` (an export
// and a component each) — this side's by row, the other's by place in the grid.
constexpr unsigned kFoldExterns = 8;
struct FoldShader {
    std::string source;
    std::vector<std::pair<int, int>> self, other;  // per slot past 3: (export, component)
    int width = 0;  // the group's folds' components: its results, component-major, rows + 1 each
};
FoldShader foldShader(const ir::Object& object, const ir::Kernel& pair);

// The grid's first pass: each row of the other side (slots 0–3 of its packed columns, at
// binding 2) in its bucket (binding 3: the bucket, ~0 for a row not folded over), counted
// per bucket (binding 4, atomics). Params: its rows, the buckets' mask, the inverse of a
// cell's width (float bits).
std::string gridCountShader();

}  // namespace psys::codegen_glsl
