#include "codegen_glsl/glsl_shaders.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "codegen_glsl/glsl_body.h"
#include "codegen_glsl/glsl_fold.h"

namespace psys::codegen_glsl {

using namespace ir;
using rt::ColumnLayout;

namespace {

uint32_t align4(uint32_t words) { return (words + 3u) & ~3u; }

// Values after the columns, 4 words each.
LaunchBlock valuesAfterColumns(LaunchBlock b, uint32_t externs, uint32_t uniforms, uint32_t params, uint32_t state,
                               uint32_t parents) {
    b.externCount = externs;
    b.uniformCount = uniforms;
    b.externs = align4(LaunchBlock::kColumns + b.columns);
    b.uniforms = b.externs + 4 * externs;
    b.params = b.uniforms + 4 * uniforms;
    b.state = b.params + 4 * params;
    b.parents = b.state + 4 * state;
    b.words = b.parents + 4 * parents;
    return b;
}

// How many of the values `op` reads (externs, uniforms) the kernel needs: up to the last it reads.
uint32_t valuesRead(const Kernel* kernel, Op op) {
    uint32_t n = 0;
    if (kernel)
        for (const Inst& i : kernel->insts())
            if (i.op == op) n = std::max(n, static_cast<uint32_t>(i.attr) + 1);
    return n;
}
uint32_t uniformValues(const Kernel& kernel) { return valuesRead(&kernel, Op::Uniform); }

// The launch's block as a uniform block: its words and 4-word values.
std::string blockAccessors(uint32_t blockWords) {
    return fmt::format(R"(layout(std140, binding = 0) uniform Launch {{ uvec4 L[{}]; }};

uint lw(uint k) {{ return L[k >> 2u][k & 3u]; }}
vec4 lv(uint k) {{ return uintBitsToFloat(L[k >> 2u]); }}
)",
                       align4(blockWords) / 4);
}

// A block per emitter in the launch's words (LaunchRecords).
std::string recordAccessors() {
    return R"(layout(std140, binding = 0) uniform Launch { uvec4 L[1]; };

uint psys_record = 0u;  // the first word of the invocation's emitter's block
uint lw(uint k) { return w[psys_record + k]; }
vec4 lv(uint k) { return uintBitsToFloat(uvec4(lw(k), lw(k + 1u), lw(k + 2u), lw(k + 3u))); }
)";
}

}  // namespace

// A double to the nearest float, ties to even, as C converts it (rt/clock.h's ages): GLSL
// does not say how float(double) rounds. The conversion is within an ulp either way, so
// x − f is exact in doubles and the neighbour toward x is the only other candidate.
std::string narrowHelper() {
    return R"(float psys_narrow(double x) {
    precise float f = float(x);
    precise double e = x - double(f);
    if (e == 0.0LF || isinf(f) || isnan(f)) return f;
    uint b = floatBitsToUint(f);
    precise float g = f == 0.0 ? uintBitsToFloat(e > 0.0LF ? 1u : 0x80000001u)
                               : uintBitsToFloat((e > 0.0LF) == (f > 0.0) ? b + 1u : b - 1u);
    precise double d = abs(x - double(g)), a = abs(e);
    return d < a || (d == a && (floatBitsToUint(g) & 1u) == 0u) ? g : f;
}
)";
}

// What a shader's bodies (codegen_glsl/glsl_body.h) call: GLSL built-ins with
// core/lanes.h's results where GLSL leaves them undefined, and the zero no compiler sees
// through, read from word `zeroWord` of the shader's `lw` (which must hold 0).
std::string mathHelpers(uint32_t zeroWord) {
    return fmt::format(R"(// A zero the GL's compiler cannot see: GLSL does not ask it to keep NaN and infinity, and
// drivers fold x · 0 to 0 even in `precise` code (Mesa does), where IEEE 754 and the
// interpreter give NaN for x = ∞ or NaN. Every float constant 0 of a kernel is this.
#define psys_zero uintBitsToFloat(lw({0}u))
#define psys_nan uintBitsToFloat(0x7fc00000u)
#define psys_inf uintBitsToFloat(0x7f800000u)
float psys_sign(float x) {{ return x > 0.0 ? 1.0 : x < 0.0 ? -1.0 : 0.0; }}
// core/lanes.h's minimumNumber and maximumNumber, from the bits (no driver folds these away).
bool psys_isnan(float x) {{ return (floatBitsToUint(x) & 0x7fffffffu) > 0x7f800000u; }}
bool psys_negative(float x) {{ return (floatBitsToUint(x) >> 31) != 0u; }}
float psys_min(float x, float y) {{ return (psys_isnan(x) || y < x || (y == x && psys_negative(y))) ? y : x; }}
float psys_max(float x, float y) {{ return (psys_isnan(x) || x < y || (y == x && !psys_negative(y))) ? y : x; }}
// IEEE 754's quotient where y is a zero (GLSL leaves x / 0 undefined: llvmpipe's is NaN,
// its reciprocal's refinement computing 0 · ∞): ±∞ by the operands' signs, NaN for 0/0.
float psys_div(float x, float y) {{
    if (y != 0.0) return x / y;
    if (psys_isnan(x) || x == 0.0) return psys_nan;
    return uintBitsToFloat(0x7f800000u | ((floatBitsToUint(x) ^ floatBitsToUint(y)) & 0x80000000u));
}}
{1}float psys_sqrt(float x) {{ return x < 0.0 ? psys_nan : sqrt(x); }}
float psys_log(float x) {{ return x < 0.0 ? psys_nan : x == 0.0 ? -psys_inf : log(x); }}
float psys_asin(float x) {{ return abs(x) > 1.0 ? psys_nan : asin(x); }}
float psys_acos(float x) {{ return abs(x) > 1.0 ? psys_nan : acos(x); }}
float psys_atan2(float y, float x) {{
    // C's atan2 where y is a zero (GLSL leaves it undefined; llvmpipe's atan(-0, -1) is NaN):
    // ±0 towards +x, ±π towards −x (−0 counts as −x), the sign of y's zero.
    if (y == 0.0 && !psys_isnan(x))
        return (x < 0.0 || (x == 0.0 && psys_negative(x))) ? (psys_negative(y) ? -3.14159265 : 3.14159265) : y;
    return atan(y, x);
}}
float psys_pow(float x, float y) {{  // C's pow: defined for every base
    if (y == 0.0 || x == 1.0) return 1.0;
    if (isnan(x) || isnan(y)) return psys_nan;
    bool integer = floor(y) == y;
    bool odd = integer && abs(y) < 16777216.0 && mod(abs(y), 2.0) == 1.0;
    if (x == 0.0) return y < 0.0 ? (odd ? psys_div(1.0, x) : psys_inf) : (odd ? x : 0.0);
    if (isinf(y)) return abs(x) == 1.0 ? 1.0 : (abs(x) > 1.0) == (y > 0.0) ? psys_inf : 0.0;
    if (x < 0.0) {{
        if (!integer) return psys_nan;
        float r = isinf(x) ? (y < 0.0 ? 0.0 : psys_inf) : pow(-x, y);
        return odd ? -r : r;
    }}
    if (isinf(x)) return y < 0.0 ? 0.0 : psys_inf;
    return pow(x, y);
}}
)", zeroWord, narrowHelper());
}

namespace {

// What every compute shader starts with: the bindings, the accessors and the helpers
// that give GLSL built-ins core/lanes.h's results where GLSL leaves them undefined. A
// column in `direct` is read and written in its own storage block (2 + its place there)
// or, past kDirectSlots, read through a buffer texture (its unit: its place less
// kDirectSlots); the others in the launch's words. The accessors' switch on a literal
// column folds away. `records`: the launch's words hold a block per emitter (a children
// launch): `lw` reads the invocation's (psys_record, set by kRecordIndex), the uniform
// block says where they are (LaunchRecords).
std::string preamble(const std::string& comment, uint32_t blockWords, const std::vector<int>& direct = {},
                     bool records = false) {
    std::string blocks, reads, writes;
    for (size_t k = 0; k < direct.size(); ++k) {
        if (k >= kDirectSlots) {
            size_t unit = k - kDirectSlots;
            blocks += fmt::format("layout(binding = {0}) uniform usamplerBuffer t{0};\n", unit);
            reads += fmt::format("case {}u: return texelFetch(t{}, int(o)).x; ", direct[k], unit);
            continue;
        }
        blocks += fmt::format("layout(std430, binding = {0}) buffer Column{0} {{ uint d{0}[]; }};\n", k + 2);
        reads += fmt::format("case {}u: return d{}[o]; ", direct[k], k + 2);
        writes += fmt::format("case {}u: d{}[o] = x; return; ", direct[k], k + 2);
    }
    return fmt::format(R"(#version 450
// {0}
layout(local_size_x = {1}) in;
layout(std430, binding = 0) buffer Words {{ uint w[]; }};
layout(std430, binding = 1) buffer Counts {{ uint counts[]; }};
{4}{8}float lf(uint k) {{ return uintBitsToFloat(lw(k)); }}
double ld(uint k) {{ return packDouble2x32(uvec2(lw(k), lw(k + 1u))); }}
uint col(uint c) {{ return lw({3}u + c); }}
uint cw(uint c, uint o) {{ switch (c) {{ {5}default: return w[o]; }} }}
void scw(uint c, uint o, uint x) {{ switch (c) {{ {6}default: w[o] = x; }} }}
float cf(uint c, uint i) {{ return uintBitsToFloat(cw(c, col(c) + i)); }}
uint cu(uint c, uint i) {{ return cw(c, col(c) + i); }}
double cd(uint c, uint i) {{ uint o = col(c) + 2u * i; return packDouble2x32(uvec2(cw(c, o), cw(c, o + 1u))); }}
void sf(uint c, uint i, float x) {{ scw(c, col(c) + i, floatBitsToUint(x)); }}
void su(uint c, uint i, uint x) {{ scw(c, col(c) + i, x); }}

{9}

)",
                       comment, kWorkGroupSize, align4(blockWords) / 4, LaunchBlock::kColumns, blocks, reads, writes,
                       LaunchBlock::kZero, records ? recordAccessors() : blockAccessors(blockWords),
                       mathHelpers(LaunchBlock::kZero));
}

const char* kIndex =
    "    uint i = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x + "
    "gl_LocalInvocationID.x;\n"
    "    if (i >= lw(0u)) return;\n";

// A children launch's invocation: its emitter's block found by a binary search of the
// blocks' first invocations (LaunchBlock::kFirstInvocation), `i` its child's place among
// that emitter's.
const char* kRecordIndex =
    "    uint i = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x + "
    "gl_LocalInvocationID.x;\n"
    "    if (i >= L[0].x) return;\n"
    "    uint lo = 0u, hi = L[0].y - 1u;\n"
    "    while (lo < hi) {\n"
    "        uint mid = (lo + hi + 1u) >> 1u;\n"
    "        if (w[L[0].z + mid * L[0].w + 1u] <= i) lo = mid; else hi = mid - 1u;\n"
    "    }\n"
    "    psys_record = L[0].z + lo * L[0].w;\n"
    "    i -= lw(1u);\n";

// A value of `width` floats at block word `word`.
std::string blockValue(uint32_t word, Type type) {
    std::string v = fmt::format("lv({}u)", word);
    if (type.isBool()) return v + ".x != 0.0";
    if (type.width == 1) return v + ".x";
    return type.width == 4 ? v : v + "." + std::string("xyzw").substr(0, type.width);
}

// A value of `width` float columns from `column` on, at row `row`.
std::string columnsValue(int column, Type type, const std::string& row) {
    if (type.isBool()) return fmt::format("cf({}u, {}) != 0.0", column, row);
    if (type.width == 1) return fmt::format("cf({}u, {})", column, row);
    std::string s = fmt::format("vec{}(", type.width);
    for (int c = 0; c < type.width; ++c) s += fmt::format("{}cf({}u, {})", c ? ", " : "", column + c, row);
    return s + ")";
}

std::string lane(const std::string& value, int width, int c) {
    return width == 1 ? value : value + "." + "xyzw"[c];
}

// Stores a value of `type` in float columns from `column` on (a bool as 1.0 or 0.0:
// columnsValue reads it back).
void storeColumns(Statements& out, int column, Type type, const std::string& value) {
    if (type.isBool()) {
        out.line(fmt::format("sf({}u, i, {} ? 1.0 : 0.0);", column, value));
        return;
    }
    for (int c = 0; c < type.width; ++c) out.line(fmt::format("sf({}u, i, {});", column + c, lane(value, type.width, c)));
}

// The shader's clock: now, dt, time, first and the row's age.
struct ClockNames {
    std::string now, dt, time, first, age;
};

ClockNames emitClock(Statements& out, rt::Clock::Source now, rt::Clock::Source dt, bool perRowCreated) {
    using S = rt::Clock::Source;
    ClockNames c;
    c.now = out.define("now", "double", now == S::PerRow ? fmt::format("cd({}u, i)", ColumnLayout::kNow)
                                                : fmt::format("ld({}u)", LaunchBlock::kNow));
    c.time = out.define("time", "float", "psys_narrow(" + c.now + ")", true);
    c.first = out.define("first", "bool", fmt::format("lw({}u) != 0u", LaunchBlock::kFirst));
    std::string created = perRowCreated ? fmt::format("cd({}u, i)", ColumnLayout::kCreated)
                                        : fmt::format("ld({}u)", LaunchBlock::kCreated);
    c.age = out.define("age", "float", emitAge(out, c.now, created), true);
    c.dt = out.define("dt", "float", dt == S::PerRow         ? fmt::format("cf({}u, i)", ColumnLayout::kDt)
                                     : dt == S::SinceCreated ? c.age
                                                             : fmt::format("lf({}u)", LaunchBlock::kDt),
                      true);
    return c;
}

// The rows kernel's uniform kernel, evaluated in the shader for this row's clock.
std::vector<std::string> inlineUniforms(Statements& out, const Kernel& uniform,
                                        const ClockNames& clock, const LaunchBlock& block) {
    Statements body("ut");
    auto leaf = [&](const Inst& inst, int) -> std::string {
        switch (inst.op) {
            case Op::Dt: return clock.dt;
            case Op::Time: return clock.time;
            case Op::Extern: return blockValue(block.externs + 4 * static_cast<uint32_t>(inst.attr), inst.type);
            case Op::DrawIndex: case Op::ObjectId: return "0u";
            case Op::First: return "false";
            default: return inst.type.isBool() ? "false" : inst.type.kind == Type::Kind::U32 ? "0u" : glslType(inst.type) + "(0.0)";
        }
    };
    std::vector<std::string> names = emitBody(body, uniform, fmt::format("lw({}u)", LaunchBlock::kSeed), leaf, "u");
    out.line("// the uniform kernel, at this row's clock");
    out.append(body.text());
    std::vector<std::string> values(uniformValues(uniform));
    for (const Yield& y : uniform.yields) {
        if (values.size() <= static_cast<size_t>(y.index)) values.resize(static_cast<size_t>(y.index) + 1);
        values[static_cast<size_t>(y.index)] = names[y.value];
    }
    return values;
}

void storeRowsYields(Statements& out, const Kernel& kernel, const ColumnLayout& l, const std::vector<std::string>& v) {
    for (const Yield& y : kernel.yields) {
        const std::string& value = v[y.value];
        Type type = kernel.at(y.value).type;
        int width = type.width;
        switch (y.kind) {
            case YieldKind::StateNext: storeColumns(out, l.stateOffset[static_cast<size_t>(y.index)], type, value); break;
            case YieldKind::Export: storeColumns(out, l.exportOffset[static_cast<size_t>(y.index)], type, value); break;
            case YieldKind::Kill:
                out.line(fmt::format("su({}u, i, {} ? 1u : 0u);", ColumnLayout::kKill, value));
                out.line(fmt::format("if ({}) atomicAdd(counts[0], 1u);", value));
                break;
            case YieldKind::Unstable: out.line(fmt::format("if ({}) atomicAdd(counts[1], 1u);", value)); break;
            case YieldKind::EmitRate: storeColumns(out, l.emitRate(y.index), type, value); break;
            case YieldKind::EmitCount: storeColumns(out, l.emitCount(y.index), type, value); break;
            case YieldKind::Visible: storeColumns(out, l.render + ColumnLayout::kVisible, type, value); break;
            case YieldKind::Position: case YieldKind::Color: case YieldKind::Size:
            case YieldKind::Rotation: case YieldKind::Frame: case YieldKind::End: case YieldKind::Trail:
                if (l.fromState(y)) break;  // drawn from the state column itself
                for (int c = 0; c < width; ++c)  // a constant lane has no column
                    if (int column = ColumnLayout::renderColumn(y.kind, y.index) + c; !l.constant(column))
                        out.line(fmt::format("sf({}u, i, {});", l.render + column, lane(value, width, c)));
                break;
            default: break;
        }
    }
}

// A render shader marks its row drawn (the rule of rt/system_draw.cpp, which the GLSL
// backend leaves to it: Backend::marksDrawn): visible, and every value finite; and counts.
void markDrawn(Statements& out, const ColumnLayout& l) {
    out.line("// drawn: visible, with a finite position, colour and size (counted)");
    std::string finite = "true";
    for (int c = ColumnLayout::kPosition; c < l.renderColumns; ++c)
        if (auto k = l.constant(c)) {
            if (!std::isfinite(*k)) finite = "false";  // every row's
        } else {
            finite += fmt::format(" && (floatBitsToUint(cf({}u, i)) & 0x7f800000u) != 0x7f800000u", l.drawnFrom(c));
        }
    std::string visible = out.define("shown", "bool", fmt::format("cf({}u, i) != 0.0", l.render + ColumnLayout::kVisible));
    std::string ok = out.define("finite", "bool", finite);
    out.line(fmt::format("sf({}u, i, {} && {} ? 1.0 : 0.0);", l.render + ColumnLayout::kVisible, visible, ok));
    out.line(fmt::format("if ({} && {}) atomicAdd(counts[2], 1u);", visible, ok));
    out.line(fmt::format("if ({} && !{}) atomicAdd(counts[3], 1u);", visible, ok));
}

const char* clockName(rt::Clock::Source s) {
    return s == rt::Clock::Source::PerRow ? "per row" : s == rt::Clock::Source::SinceCreated ? "since creation" : "uniform";
}

}  // namespace

std::vector<int> keptColumns(const Kernel& kernel, const ColumnLayout& l) {
    std::vector<int> kept;
    auto range = [&kept](int first, int width) {
        for (int c = 0; c < width; ++c) kept.push_back(first + c);
    };
    // What is drawn stays on the GPU (the viewer draws from it): the render shader writes
    // `visible` for every row, and the render columns not drawn from the state's.
    if (kernel.kind == KernelKind::Render)
        for (int c = 0; c < l.renderColumns; ++c)
            if (l.drawnFrom(c) == l.render + c && !l.constant(c)) kept.push_back(l.render + c);
    for (const Yield& y : kernel.yields) {
        int width = kernel.at(y.value).type.width;
        if (y.kind == YieldKind::StateNext) range(l.stateOffset[static_cast<size_t>(y.index)], width);
        if (y.kind == YieldKind::Export) range(l.exportOffset[static_cast<size_t>(y.index)], width);
    }
    std::sort(kept.begin(), kept.end());
    kept.erase(std::unique(kept.begin(), kept.end()), kept.end());
    return kept;
}

std::vector<int> directColumns(const Kernel& kernel, const ColumnLayout& l) {
    const std::vector<int> kept = keptColumns(kernel, l);
    std::vector<int> direct = kept;
    if (direct.size() > kDirectSlots) direct.resize(kDirectSlots);  // written: storage blocks only
    auto add = [&](int c) {  // read only (a kept column past the blocks stays in the words)
        if (std::find(kept.begin(), kept.end(), c) == kept.end() &&
            std::find(direct.begin(), direct.end(), c) == direct.end())
            direct.push_back(c);
    };
    for (const Inst& i : kernel.insts())
        if (i.op == Op::StateRead)
            for (int c = 0; c < i.type.width; ++c) add(l.stateOffset[static_cast<size_t>(i.attr)] + c);
    add(ColumnLayout::kCreated);  // 8 bytes a row
    add(l.total);                 // the mask
    for (const Inst& i : kernel.insts()) {
        if (i.op == Op::Param)
            for (int c = 0; c < i.type.width; ++c) add(l.paramOffset[static_cast<size_t>(i.attr)] + c);
        if (i.op == Op::ObjectId) add(ColumnLayout::kIds);
    }
    for (const auto& p : l.parentColumns)  // gathered on the GPU (Memory::gather)
        for (int c = 0; c < p.width; ++c) add(p.offset + c);
    if (direct.size() > kDirectSlots + kTextureSlots) direct.resize(kDirectSlots + kTextureSlots);
    return direct;
}

LaunchBlock rowsBlock(const Kernel& kernel, const Kernel* uniform, const ColumnLayout& layout) {
    LaunchBlock b;
    b.columns = static_cast<uint32_t>(layout.total) + 1;  // the mask last
    uint32_t externs = std::max(valuesRead(&kernel, Op::Extern), valuesRead(uniform, Op::Extern));
    return valuesAfterColumns(b, externs, uniformValues(kernel), 0, 0, 0);
}

LaunchBlock childrenBlock(const Object& object, const Kernel& spawn, const ColumnLayout& layout) {
    LaunchBlock b;
    b.columns = static_cast<uint32_t>(rt::argumentColumns(spawn).total);
    return valuesAfterColumns(b, valuesRead(&spawn, Op::Extern), 0, static_cast<uint32_t>(object.params.size()),
                              static_cast<uint32_t>(object.state.size()),
                              static_cast<uint32_t>(layout.parentColumns.size()));
}

std::string rowsShader(const Object& object, const Kernel& kernel, rt::Clock::Source now, rt::Clock::Source dt,
                       const Kernel* uniform) {
    ColumnLayout l = rt::columnLayout(object, kernel);
    LaunchBlock block = rowsBlock(kernel, uniform, l);
    std::string text = preamble(fmt::format("object `{}`, kernel `{}`, clock: now {}, dt {}", object.name,
                                            kernelName(kernel.kind), clockName(now), clockName(dt)),
                                block.words, directColumns(kernel, l));
    Statements out("t");
    bool kills = kernel.findOne(YieldKind::Kill) != nullptr;
    bool render = kernel.kind == KernelKind::Render;
    if (kills) out.line(fmt::format("su({}u, i, 0u);", ColumnLayout::kKill));
    if (render)
        out.line(fmt::format("if (cu({}u, i) == 0u) {{ sf({}u, i, 0.0); return; }}  // masked out: not drawn", l.total,
                             l.render + ColumnLayout::kVisible));
    else
        out.line(fmt::format("if (cu({}u, i) == 0u) return;  // masked out", l.total));
    ClockNames clock = emitClock(out, now, dt, true);
    bool perRow = rt::Clock::perRow(now, dt);
    std::vector<std::string> uniforms;
    if (perRow && uniform) uniforms = inlineUniforms(out, *uniform, clock, block);
    const Kernel& k = kernel;
    auto leaf = [&](const Inst& inst, int parentOrdinal) -> std::string {
        switch (inst.op) {
            case Op::Param: return columnsValue(l.paramOffset[static_cast<size_t>(inst.attr)], inst.type, "i");
            case Op::StateRead: return columnsValue(l.stateOffset[static_cast<size_t>(inst.attr)], inst.type, "i");
            case Op::Extern: return blockValue(block.externs + 4 * static_cast<uint32_t>(inst.attr), inst.type);
            case Op::Uniform:
                if (!uniforms.empty()) return uniforms.at(static_cast<size_t>(inst.attr));
                return blockValue(block.uniforms + 4 * static_cast<uint32_t>(inst.attr), inst.type);
            case Op::Age: return clock.age;
            case Op::Dt: return clock.dt;
            case Op::Time: return clock.time;
            case Op::First: return clock.first;
            case Op::ParentExport: case Op::ParentAlive: case Op::ParentAge: case Op::Fold:
                return columnsValue(l.parentColumns.at(static_cast<size_t>(parentOrdinal)).offset, inst.type, "i");
            case Op::ObjectId: return fmt::format("cu({}u, i)", ColumnLayout::kIds);
            case Op::DrawIndex: return fmt::format("lw({}u)", LaunchBlock::kDraw);
            default: return glslType(inst.type) + "(0)";
        }
    };
    std::vector<std::string> values = emitBody(out, k, fmt::format("lw({}u)", LaunchBlock::kSeed), leaf);
    storeRowsYields(out, k, l, values);
    if (render) markDrawn(out, l);
    return text + "void main() {\n" + kIndex + out.text() + "}\n";
}

std::vector<int> directArguments(const Kernel& spawn) {
    auto columns = static_cast<size_t>(rt::argumentColumns(spawn).total);
    std::vector<int> direct;
    if (columns <= kDirectSlots)
        for (size_t c = 0; c < columns; ++c) direct.push_back(static_cast<int>(c));
    return direct;
}

std::string childrenShader(const Object& object, const Kernel& spawn) {
    ColumnLayout l = rt::columnLayout(object, spawn);
    LaunchBlock block = childrenBlock(object, spawn, l);
    std::string text = preamble(fmt::format("object `{}`, kernel `spawn.{}` (creates `{}`): one invocation per child "
                                            "of each emitter of the launch",
                                            object.name, spawn.site,
                                            object.emits.at(static_cast<size_t>(spawn.site)).target),
                                block.words, directArguments(spawn), true);
    Statements out("t");
    using S = rt::Clock::Source;
    ClockNames clock = emitClock(out, S::Uniform, S::Uniform, false);
    auto leaf = [&](const Inst& inst, int parentOrdinal) -> std::string {
        switch (inst.op) {
            case Op::Param: return blockValue(block.params + 4 * static_cast<uint32_t>(inst.attr), inst.type);
            case Op::StateRead: return blockValue(block.state + 4 * static_cast<uint32_t>(inst.attr), inst.type);
            case Op::Extern: return blockValue(block.externs + 4 * static_cast<uint32_t>(inst.attr), inst.type);
            case Op::Age: return clock.age;
            case Op::Dt: return clock.dt;
            case Op::Time: return clock.time;
            case Op::First: return clock.first;
            case Op::ParentExport: case Op::ParentAlive: case Op::ParentAge: case Op::Fold:
                return blockValue(block.parents + 4 * static_cast<uint32_t>(parentOrdinal), inst.type);
            case Op::ObjectId: return fmt::format("lw({}u)", LaunchBlock::kObjectId);
            case Op::DrawIndex:
                return inst.attr == 1 ? fmt::format("lw({}u) + i", LaunchBlock::kFirstChild)
                                      : fmt::format("lw({}u)", LaunchBlock::kDraw);
            default: return glslType(inst.type) + "(0)";
        }
    };
    std::vector<std::string> values = emitBody(out, spawn, fmt::format("lw({}u)", LaunchBlock::kSeed), leaf);
    std::vector<size_t> first = rt::argumentColumns(spawn).first;
    for (const Yield& y : spawn.yields)
        if (y.kind == YieldKind::EmitArg)
            storeColumns(out, static_cast<int>(first[static_cast<size_t>(y.sub)]), spawn.at(y.value).type, values[y.value]);
    return text + "void main() {\n" + kRecordIndex + out.text() + "}\n";
}

std::string drawVertexShader() {
    return R"(#version 450
// draw: one point per row of a type's render columns (DrawColumns), read straight from
// the words of the columns; rows that are not visible give no pixels.
layout(std430, binding = 0) readonly buffer Words { uint w[]; };
uniform uint columns[9];  // first words of visible, x, y, z, r, g, b, a, size
uniform float constants[9];  // the value of a column whose first word is 0xffffffff (none)
uniform mat4 view;
uniform mat4 projection;
uniform float reference;  // pixels per unit of size at depth 1
out vec4 colour;
float column(int c) {
    return columns[c] == 0xffffffffu ? constants[c] : uintBitsToFloat(w[columns[c] + uint(gl_VertexID)]);
}
void main() {
    if (column(0) == 0.0) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
        gl_PointSize = 0.0;
        colour = vec4(0.0);
        return;
    }
    vec4 eye = view * vec4(column(1), column(2), column(3), 1.0);
    gl_Position = projection * eye;
    gl_PointSize = clamp(column(8) * reference / max(-eye.z, 1e-3), 1.0, 256.0);
    colour = vec4(column(4), column(5), column(6), column(7));
}
)";
}

std::string drawFragmentShader() {
    return R"(#version 450
// draw: a round point with a soft rim
in vec4 colour;
out vec4 fragment;
void main() {
    vec2 d = gl_PointCoord * 2.0 - 1.0;
    float r2 = dot(d, d);
    if (r2 > 1.0) discard;
    float edge = 1.0 - smoothstep(0.4, 1.0, r2);
    fragment = vec4(colour.rgb, colour.a * edge);
}
)";
}

std::vector<NamedShader> moduleShaders(const rt::Plan& plan) {
    std::vector<NamedShader> shaders;
    using S = rt::Clock::Source;
    for (const rt::Plan::Rows& r : plan.rows) {
        auto served = uniformFor(r.kernel->kind);
        const Kernel* uniform = served ? r.object->kernel(*served) : nullptr;
        std::string clock = r.now == S::PerRow ? "per_row" : "uniform";
        shaders.push_back({fmt::format("{}.{}.{}.comp", r.object->name, kernelName(r.kernel->kind), clock),
                           rowsShader(*r.object, *r.kernel, r.now, r.dt, uniform)});
    }
    for (const rt::Plan::Children& c : plan.children)
        shaders.push_back({fmt::format("{}.spawn{}.comp", c.object->name, c.spawn->site),
                           childrenShader(*c.object, *c.spawn)});
    // The neighbour folds (gpu/gl_fold.cpp runs them): each group's, and the grid's count.
    std::vector<const Object*> folding;
    for (const rt::Plan::Rows& r : plan.rows)
        if (!r.object->neighbours.empty() && std::find(folding.begin(), folding.end(), r.object) == folding.end())
            folding.push_back(r.object);
    for (const Object* o : folding)
        for (const Kernel& k : o->kernels)
            if (k.kind == KernelKind::Pair)
                shaders.push_back({fmt::format("{}.fold{}.comp", o->name, k.site), foldShader(*o, k).source});
    if (!folding.empty()) shaders.push_back({"grid.count.comp", gridCountShader()});
    shaders.push_back({"draw.vert", drawVertexShader()});
    shaders.push_back({"draw.frag", drawFragmentShader()});
    return shaders;
}

}  // namespace psys::codegen_glsl
