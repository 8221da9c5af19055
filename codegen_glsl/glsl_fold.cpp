#include "codegen_glsl/glsl_fold.h"

#include <algorithm>

#include <fmt/format.h>

#include "codegen_glsl/glsl_body.h"
#include "codegen_glsl/glsl_shaders.h"
#include "core/fold.h"

namespace psys::codegen_glsl {

using namespace ir;

namespace {

// psys_cell (a position component's cell) and psys_bucket (a cell's bucket), as the host
// computes them: `inverse` and `mask` are GLSL expressions of the shader's parameters.
std::string gridFunctions(const std::string& inverse, const std::string& mask) {
    Statements cell("c"), bucket("b");
    std::string cellValue = emitCell(cell, "p", inverse);
    std::string bucketValue = emitCellBucket(bucket, "x", "y", "z", mask);
    return fmt::format("uint psys_cell(float p) {{\n{}    return {};\n}}\nuint psys_bucket(uint x, uint y, uint z) {{\n{}    "
                       "return {};\n}}\n",
                       cell.text(), cellValue, bucket.text(), bucketValue);
}

}  // namespace

FoldShader foldShader(const Object& object, const Kernel& pair) {
    FoldShader f;
    auto slot = [&](std::vector<std::pair<int, int>>& slots, int e, int c) {
        auto it = std::find(slots.begin(), slots.end(), std::pair{e, c});
        if (it == slots.end()) it = slots.insert(slots.end(), {e, c});
        return 4 + static_cast<int>(it - slots.begin());
    };
    // The folds' accumulators: the group's folds' components in fold order.
    std::vector<int> first(object.folds.size(), -1);
    std::string declare, store;
    for (size_t k = 0; k < object.folds.size(); ++k) {
        const Fold& fold = object.folds[k];
        if (fold.group != pair.site) continue;
        first[k] = f.width;
        for (int c = 0; c < fold.type.width; ++c, ++f.width) {
            declare += fmt::format("    float a{} = {};\n", f.width, floatLiteral(core::emptyFold(fold.reduce)));
            store += fmt::format("    res[{}u * (rows + 1u) + i] = floatBitsToUint(a{});\n", f.width, f.width);
        }
    }
    // The terms, for object `i` and the neighbour at place `j` of the grid.
    Statements body("t");
    auto leaf = [&](const Inst& inst, int) -> std::string {
        std::string lanes;
        for (int c = 0; c < inst.type.width; ++c) {
            if (inst.op == Op::NeighbourExport) {
                bool other = inst.attr2 == 1;
                int s = slot(other ? f.other : f.self, inst.attr, c);
                std::string x = fmt::format("{}({}u, {})", other ? "ov" : "sv", s, other ? "j" : "i");
                lanes += (c ? ", " : "") + (inst.type.isBool() ? "(" + x + " != 0.0)" : x);  // (a bool: 0 or 1)
            } else if (inst.op == Op::Extern) {
                lanes += fmt::format("{}uintBitsToFloat(lw({}u))", c ? ", " : "", kFoldExterns + 4 * inst.attr + c);
            } else {
                throw std::runtime_error(unexpectedOp(inst, "the GLSL backend's pair kernels"));
            }
        }
        return inst.type.width == 1 ? lanes : fmt::format("vec{}({})", inst.type.width, lanes);
    };
    std::vector<std::string> values = emitBody(body, pair, "0u", leaf);
    const char* lane = "xyzw";
    for (const Yield& y : pair.yields) {
        const Fold& fold = object.folds.at(static_cast<size_t>(y.index));
        for (int c = 0; c < fold.type.width; ++c) {
            std::string a = fmt::format("a{}", first[static_cast<size_t>(y.index)] + c);
            std::string term = fold.type.width == 1 ? values[y.value] : values[y.value] + "." + lane[c];
            switch (fold.reduce) {  // core::combine
                case core::Reduce::Min: body.line(fmt::format("{0} = {1} < {0} ? {1} : {0};", a, term)); break;
                case core::Reduce::Max: body.line(fmt::format("{0} = {1} > {0} ? {1} : {0};", a, term)); break;
                default: body.line(fmt::format("{0} = {0} + {1};", a, term)); break;
            }
        }
    }
    f.source = fmt::format(R"(#version 450
// object `{0}`: its folds over `{1}` within {2} (group #{3})
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Words {{ uint w[]; }};
layout(std430, binding = 2) readonly buffer Self {{ uint sw[]; }};
layout(std430, binding = 3) readonly buffer Other {{ uint ow[]; }};
layout(std430, binding = 4) readonly buffer Start {{ uint start[]; }};
layout(std430, binding = 5) readonly buffer Sorted {{ uint sorted[]; }};
layout(std430, binding = 6) writeonly buffer Out {{ uint res[]; }};
uint lw(uint k) {{ return w[k]; }}
{4}
float sv(uint s, uint i) {{ return uintBitsToFloat(sw[s * lw(0u) + i]); }}
float ov(uint s, uint j) {{ return uintBitsToFloat(ow[s * lw(1u) + j]); }}  // (by place in the grid)
{5}void main() {{
    uint k = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
    uint rows = lw(0u);
    if (k > rows) return;
    if (k == rows || sw[k] == 0u) {{  // a row no walk writes: the row of empty folds, or a dead one
        uint i = k;
{6}{8}    }}
    // The object invocation k walks: where the sides are one type, the grid's k-th (the
    // objects of a cell walk side by side, reading the same buckets), else row k.
    uint i = k;
    if (lw(5u) != 0u) {{
        if (k >= start[lw(2u) + 1u]) return;
        i = sorted[k];
    }} else if (k == rows || sw[k] == 0u) {{
        return;
    }}
{6}    {{
        precise float px = sv(1u, i), py = sv(2u, i), pz = sv(3u, i);
        uint cx = psys_cell(px), cy = psys_cell(py), cz = psys_cell(pz);
        uint b[27];
        for (uint n = 0u; n < 27u; ++n) b[n] = psys_bucket(cx + n % 3u - 1u, cy + n / 3u % 3u - 1u, cz + n / 9u - 1u);
        for (int s = 1; s < 27; ++s) {{  // ascending, as the host walks them
            uint v = b[s];
            int t = s - 1;
            while (t >= 0 && b[t] > v) {{ b[t + 1] = b[t]; --t; }}
            b[t + 1] = v;
        }}
        float radius2 = uintBitsToFloat(lw(4u));
        for (int s = 0; s < 27; ++s) {{
            if (s > 0 && b[s] == b[s - 1]) continue;
            for (uint j = start[b[s]]; j < start[b[s] + 1u]; ++j) {{
                if (lw(5u) != 0u && sorted[j] == i) continue;
                precise float dx = ov(1u, j) - px, dy = ov(2u, j) - py, dz = ov(3u, j) - pz;
                precise float d2 = dx * dx + dy * dy + dz * dz;
                if (!(d2 <= radius2)) continue;
{7}            }}
        }}
    }}
{8}}}
)",
                           object.name, object.neighbours.at(static_cast<size_t>(pair.site)).target,
                           object.neighbours.at(static_cast<size_t>(pair.site)).radius, pair.site, mathHelpers(6),
                           gridFunctions("uintBitsToFloat(lw(3u))", "lw(2u)"), declare, body.text(), store);
    return f;
}

std::string gridCountShader() {
    return fmt::format(R"(#version 450
layout(local_size_x = 256) in;
layout(std140, binding = 1) uniform Params {{ uvec4 P[3]; }};
uint param(uint k) {{ return P[k >> 2u][k & 3u]; }}
layout(std430, binding = 2) readonly buffer Other {{ uint ow[]; }};
layout(std430, binding = 3) writeonly buffer BucketOf {{ uint bucketOf[]; }};
layout(std430, binding = 4) buffer Counts {{ uint counts[]; }};
{0}void main() {{
    uint r = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
    uint rows = param(0u);
    if (r >= rows) return;
    if (ow[r] == 0u) {{
        bucketOf[r] = 0xffffffffu;
        return;
    }}
    uint b = psys_bucket(psys_cell(uintBitsToFloat(ow[rows + r])), psys_cell(uintBitsToFloat(ow[2u * rows + r])),
                         psys_cell(uintBitsToFloat(ow[3u * rows + r])));
    bucketOf[r] = b;
    atomicAdd(counts[b], 1u);
}}
)",
                       gridFunctions("uintBitsToFloat(param(2u))", "param(1u)"));
}

}  // namespace psys::codegen_glsl
