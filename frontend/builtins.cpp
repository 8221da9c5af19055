#include "frontend/builtins.h"

#include "core/instances.h"
#include "core/integrators.h"

#include <array>
#include <cstdio>
#include <string>
#include <iterator>
#include <vector>

namespace psys {
namespace {

using R = BuiltinRule;

// The functions that are not one op of core/ops.h (those come from its rows: PSYS_BUILTIN,
// PSYS_MAPS), each expanded by lowering (lower/lower_calls.cpp).
constexpr BuiltinFunction kOwnFunctions[] = {
    // componentwise maths (beside the ops')
    {"clamp", 1, 3, R::Componentwise, 0, "clamp(x: T, lo: T|float = 0, hi: T|float = 1) -> T"},
    {"saturate", 1, 1, R::Componentwise, 0, "saturate(x: T) -> T"},
    {"mix", 3, 3, R::Componentwise, 0, "mix(a: T, b: T, t: T|float) -> T"},
    {"lerp", 3, 3, R::Componentwise, 0, "lerp(a: T, b: T, t: T|float) -> T"},
    {"smoothstep", 3, 3, R::Componentwise, 0, "smoothstep(e0: T|float, e1: T|float, x: T) -> T"},
    {"radians", 1, 1, R::Componentwise, 0, "radians(degrees: T) -> T"},
    {"degrees", 1, 1, R::Componentwise, 0, "degrees(radians: T) -> T"},
    // geometry
    {"length", 1, 1, R::ToScalar, 0, "length(v: T) -> float"},
    {"distance", 2, 2, R::ToScalar, 0, "distance(a: T, b: T) -> float"},
    {"dot", 2, 2, R::ToScalar, 0, "dot(a: T, b: T) -> float"},
    {"normalize", 1, 1, R::SameVector, 0, "normalize(v: vecN) -> vecN"},
    {"reflect", 2, 2, R::SameVector, 0, "reflect(v: vecN, normal: vecN) -> vecN"},
    {"cross", 2, 2, R::Cross, 0, "cross(a: vec3, b: vec3) -> vec3"},
    {"rotate_x", 2, 2, R::Rotate, 0, "rotate_x(v: vec3, angle: float) -> vec3"},
    {"rotate_y", 2, 2, R::Rotate, 0, "rotate_y(v: vec3, angle: float) -> vec3"},
    {"rotate_z", 2, 2, R::Rotate, 0, "rotate_z(v: vec3, angle: float) -> vec3"},
    // constructors
    {"vec2", 1, 2, R::Construct, 2, "vec2(x: float) or vec2(components…) -> vec2"},
    {"vec3", 1, 3, R::Construct, 3, "vec3(x: float) or vec3(components…) -> vec3"},
    {"vec4", 1, 4, R::Construct, 4, "vec4(x: float) or vec4(components…) -> vec4"},
    {"rgba", 1, 4, R::Construct, 4, "rgba(r, g, b, a) -> color"},
    // time and state
    {"integrate", 1, 1, R::Integrate, 0, "integrate(x: T) -> T"},
    {"derive", 1, 1, R::Integrate, 0, "derive(x: T) -> T"},
    {"snapshot", 1, 1, R::Snapshot, 0, "snapshot(x) -> x"},
    {"prev", 1, 1, R::Prev, 0, "prev(x) -> x"},
    // neighbours (core/fold.h)
    {"near_sum", 3, 3, R::Neighbours, 0, "near_sum(type, radius, term: T) -> T: the sum of the term over the objects of the type within the radius"},
    {"near_min", 3, 3, R::Neighbours, 0, "near_min(type, radius, term: T) -> T: the least term (componentwise) over the objects within the radius"},
    {"near_max", 3, 3, R::Neighbours, 0, "near_max(type, radius, term: T) -> T: the greatest term (componentwise) over the objects within the radius"},
    {"near_count", 2, 2, R::Neighbours, 0, "near_count(type, radius) -> float: how many objects of the type lie within the radius"},
    // randomness
    {"rand", 0, 0, R::Random, 1, "rand() -> float in [0, 1]"},
    {"rand2", 0, 0, R::Random, 2, "rand2() -> vec2 in [0, 1]²"},
    {"rand3", 0, 0, R::Random, 3, "rand3() -> vec3 in [0, 1]³"},
    {"rand4", 0, 0, R::Random, 4, "rand4() -> vec4 in [0, 1]⁴"},
    {"nrand", 0, 0, R::Random, 1, "nrand() -> float in [-1, 1]"},
    {"nrand2", 0, 0, R::Random, 2, "nrand2() -> vec2 in [-1, 1]²"},
    {"nrand3", 0, 0, R::Random, 3, "nrand3() -> vec3 in [-1, 1]³"},
    {"nrand4", 0, 0, R::Random, 4, "nrand4() -> vec4 in [-1, 1]⁴"},
};

const BuiltinConstant kConstants[] = {
    {"pi", Type::scalar(), {3.14159265358979f, 0, 0, 0}},
    {"tau", Type::scalar(), {6.28318530717959f, 0, 0, 0}},
    {"origin", Type::vec(3), {0, 0, 0, 0}},
    {"red", Type::vec(4), {1, 0, 0, 1}},
    {"green", Type::vec(4), {0, 1, 0, 1}},
    {"blue", Type::vec(4), {0, 0, 1, 1}},
    {"white", Type::vec(4), {1, 1, 1, 1}},
    {"black", Type::vec(4), {0, 0, 0, 1}},
    {"grey", Type::vec(4), {0.5f, 0.5f, 0.5f, 1}},
    {"gray", Type::vec(4), {0.5f, 0.5f, 0.5f, 1}},
    {"yellow", Type::vec(4), {1, 1, 0, 1}},
    {"cyan", Type::vec(4), {0, 1, 1, 1}},
    {"magenta", Type::vec(4), {1, 0, 1, 1}},
    {"orange", Type::vec(4), {1, 0.5f, 0, 1}},
    {"purple", Type::vec(4), {0.5f, 0, 0.5f, 1}},
    {"transparent", Type::vec(4), {0, 0, 0, 0}},
};

constexpr BuiltinAttribute kAttributes[] = {
    {"integrator", "@integrator(method)", "how `integrate` advances this object's equations (docs/accuracy.md)"},
    {"step", "@step(seconds)", "a fixed sub-step: updates run in steps of at most this many seconds"},
    {"tolerance", "@tolerance(metres[, seconds])",
     "the largest position error accepted over the first `seconds` (10 when not given): the compiler chooses the "
     "cheapest integrator, sub-step and precision that meet it (psysc check --explain; docs/accuracy.md)"},
    {"precision", "@precision(float|double)",
     "how the state is kept: float (the default), or double: pairs of floats, 48 significant bits, on every "
     "backend (docs/accuracy.md); about 1e-13 m on a projectile where floats reach 1e-5 m"},
    {"capacity", "@capacity(count)", "the most objects of this type alive at once; emissions beyond it are dropped"},
    {"shape", "@shape(soft|disc|ring|star|smoke)", "a sprite's shape (soft, the default: a disc with a soft edge)"},
    {"texture", "@texture(\"file.png\"[, columns, rows])",
     "a sprite's image (PNG, next to the program), or a flip-book of columns × rows frames that `frame` picks; "
     "it takes the place of @shape"},
    {"blend", "@blend(add|alpha)", "how the type's colours combine with what is behind: added (light, the default) or "
                                   "alpha-blended over it (smoke, dust; drawn back to front)"},
};

constexpr std::string_view kKeywords[] = {"import", "const", "fn", "let", "extern", "range", "trigger", "object",
                                          "spawn", "point", "sprite", "streak", "trail", "kill", "when", "on", "emit", "notify", "at", "per", "second", "count",
                                          "if", "then", "else", "true", "false"};

}  // namespace

std::span<const BuiltinAttribute> builtinAttributes() { return kAttributes; }

std::string_view attributeDoc(std::string_view name) {
    for (const BuiltinAttribute& a : kAttributes)
        if (a.name == name) return a.doc;
    return {};
}

std::span<const std::string_view> keywords() { return kKeywords; }

// The ops that are built-in functions, in the table's order, then the rest.
std::span<const BuiltinFunction> builtinFunctions() {
    static const std::vector<BuiltinFunction> all = [] {
        std::vector<BuiltinFunction> out;
        for (size_t i = 0; i < core::kOpCount; ++i) {
            auto op = static_cast<core::Op>(i);
            const core::OpInfo& info = core::opInfo(op);
            if (!info.spelling.builtin.empty())
                out.push_back({info.name, info.arity, info.arity, R::Componentwise, 0, info.spelling.builtin, op});
        }
        out.insert(out.end(), std::begin(kOwnFunctions), std::end(kOwnFunctions));
        return out;
    }();
    return all;
}

int findBuiltinFunction(std::string_view name) {
    std::span<const BuiltinFunction> all = builtinFunctions();
    for (size_t i = 0; i < all.size(); ++i)
        if (all[i].name == name) return static_cast<int>(i);
    return -1;
}

const BuiltinFunction& builtinFunction(int index) { return builtinFunctions()[static_cast<size_t>(index)]; }

bool isTemporal(BuiltinRule rule) {
    return rule == R::Integrate || rule == R::Snapshot || rule == R::Prev;
}

std::span<const BuiltinConstant> builtinConstants() { return kConstants; }

int findBuiltinConstant(std::string_view name) {
    for (size_t i = 0; i < std::size(kConstants); ++i)
        if (kConstants[i].name == name) return static_cast<int>(i);
    return -1;
}

constexpr InstanceMember kInstanceMembers[] = {
    {"pos", core::kInstancePosition, 0, 3, "where the instance is: its transform's translation"},
    {"x", core::kInstanceAxisX, 0, 3, "the instance's x axis: its transform's first column (its length the scale)"},
    {"y", core::kInstanceAxisY, 0, 3, "the instance's y axis: its transform's second column"},
    {"z", core::kInstanceAxisZ, 0, 3, "the instance's z axis: its transform's third column"},
    {"index", core::kInstanceIndex, 3, 1, "the instance's index (0 for the system's own)"},
};

std::span<const InstanceMember> instanceMembers() { return kInstanceMembers; }

int findInstanceMember(std::string_view name) {
    for (size_t i = 0; i < std::size(kInstanceMembers); ++i)
        if (kInstanceMembers[i].name == name) return static_cast<int>(i);
    return -1;
}

constexpr std::string_view kVariables[] = {"age", "time", "dt"};

std::span<const std::string_view> builtinVariables() { return kVariables; }

bool isBuiltinVariable(std::string_view name) {
    for (std::string_view v : kVariables)
        if (v == name) return true;
    return false;
}

std::span<const std::string_view> integratorNames() { return core::kIntegratorNames; }

std::string integratorDoc(std::string_view name) {
    using core::Integrator;
    auto method = core::integratorFromName(name);
    if (!method) return "";
    std::string what, order = "order 1";
    switch (*method) {
        case Integrator::Euler: what = "Euler's step: every integrand at the start of the update"; break;
        case Integrator::SemiImplicit:
            what = "the default: Euler's step with each integrand in equation order (a velocity, then the "
                   "position from the new velocity)";
            break;
        case Integrator::Midpoint: what = "one more stage, at the middle of the update"; order = "order 2"; break;
        case Integrator::Rk2: what = "Heun's method: the slopes at the start and at the end, averaged"; order = "order 2"; break;
        case Integrator::Rk4: what = "the classical Runge–Kutta method: four stages"; order = "order 4"; break;
        case Integrator::Exponential:
            what = "Euler's step with each integral's linear decay (a − k·y) solved exactly";
            order = "order 1, exact while a and k are fixed over the step";
            break;
        case Integrator::Exact: what = "the closed form (an error where there is none)"; order = "exact"; break;
        case Integrator::Leapfrog:
            what = "velocity Verlet: half a kick, a drift, half a kick; keeps an orbit's or a spring's energy "
                   "for any number of periods";
            order = "order 2";
            break;
        case Integrator::Bs3:
            what = "the Bogacki–Shampine 3(2) pair: each object's steps shrink and grow within the update to "
                   "keep its error estimate within its @tolerance (else 1e-3 m over 10 s), up to four tries an "
                   "update";
            order = "order 3";
            break;
    }
    double limit = core::stabilityLimit(*method);
    char stable[96];
    if (limit > 0) std::snprintf(stable, sizeof stable, "stable for y' = -k·y while k·h < %.4g", limit);
    else if (*method == Integrator::Bs3)
        std::snprintf(stable, sizeof stable, "stable while four tries an update suffice (k·h up to 1); beyond, counted");
    else std::snprintf(stable, sizeof stable, "stable for any decay");
    return what + "; " + order + "; " + stable + ".";
}

namespace {

struct Word {
    std::string_view name, doc;
};

constexpr Word kCommandDocs[] = {
    {"point", "draws the object as a round dot `size` pixels across at the reference distance"},
    {"sprite", "draws the object as a camera-facing square `size` world units across, turned by `rotation` radians, "
               "of the type's @shape or @texture (`frame` picks a flip-book's frame); rotation and frame may be left out"},
    {"streak", "draws a band `width` world units wide from `start` to `end`"},
    {"trail", "draws a ribbon through the object's positions at its last `length` updates (this one first), `width` "
              "world units wide at its head, narrowing and fading to nothing at its tail"},
    {"kill", "the object dies: at once (`kill;`), or at the first update the condition holds (`kill when c;`)"},
    {"emit", "creates objects of a type: once at creation, `at R per second` while alive, `count N` at a time; the "
             "arguments are the new objects' parameters"},
    {"notify", "sends an event the host receives, with values (`notify \"hit\"(pos);`)"},
    {"when", "the commands inside run at the updates where the condition holds"},
    {"on", "the commands inside run when the event happens (`on death { … }`: as the object dies)"},
    {"spawn", "creates an object of a type when the system starts"},
};

constexpr Word kShapeDocs[] = {
    {"soft", "a disc with a soft edge (the default)"},
    {"disc", "a disc with a hard edge"},
    {"ring", "a ring"},
    {"star", "a four-pointed flare"},
    {"smoke", "a puff of value noise"},
};

constexpr Word kBlendDocs[] = {
    {"add", "colours are added to what is behind (light: sparks, fire, glows; order does not matter); the default"},
    {"alpha", "colours are blended over what is behind by their alpha (matter: smoke, dust; drawn back to front)"},
};

constexpr Word kTypeDocs[] = {
    {"bool", "true or false"},
    {"float", "a number (32-bit floating point)"},
    {"scalar", "a number: another name of float"},
    {"vec2", "two floats (x, y)"},
    {"vec3", "three floats (x, y, z)"},
    {"point", "a place: three floats, another name of vec3"},
    {"vector", "a direction and length: three floats, another name of vec3"},
    {"vec4", "four floats (x, y, z, w)"},
    {"color", "a colour: red, green, blue, alpha; another name of vec4"},
};

template <size_t N>
std::string_view lookup(const Word (&words)[N], std::string_view name) {
    for (const Word& w : words)
        if (w.name == name) return w.doc;
    return {};
}

}  // namespace

std::string_view commandDoc(std::string_view keyword) { return lookup(kCommandDocs, keyword); }
std::string_view shapeDoc(std::string_view shape) { return lookup(kShapeDocs, shape); }
std::string_view blendDoc(std::string_view blend) { return lookup(kBlendDocs, blend); }
std::string_view typeDoc(std::string_view type) { return lookup(kTypeDocs, type); }

Type drawParamType(const core::DrawParam& p) { return p.width == 1 ? Type::scalar() : Type::vec(p.width); }

std::string drawCallSignature(core::DrawKind kind) {
    core::DrawSignature signature = core::drawSignature(kind);
    std::string out = std::string(core::drawKindName(kind)) + "(";
    for (size_t i = 0; i < signature.count; ++i)
        out += (i ? ", " : "") + std::string(signature.params[i].name) + ": " + drawParamType(signature.params[i]).str();
    return out + ")";
}

}  // namespace psys
