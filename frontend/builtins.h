// The built-in functions, variables and constants of .psys, with their typing rules.
//
// One list, so the type checker, `--emit=ast`, the editor support and lowering agree on
// what exists: the functions that are exactly one op come from core/ops.h's rows (their
// signature there), the rest are this file's table. Numeric functions work on float and vectors componentwise, and a float
// argument broadcasts to the width of the others (as the thesis's NOp class did).
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "core/draw.h"
#include "core/ops.h"
#include "frontend/types.h"

namespace psys {

enum class BuiltinRule {
    Componentwise,   // f(T, …) -> T, float arguments broadcast: sin, min, clamp, mix, pow, …
    ToScalar,        // f(T, …) -> float: length, distance, dot
    SameVector,      // f(vecN, …) -> vecN: normalize, reflect
    Cross,           // cross(vec3, vec3) -> vec3
    Rotate,          // rotate_y(vec3, float) -> vec3
    Construct,       // vec2/vec3/vec4(components…) or (float) broadcast
    Integrate,       // integrate(T) / derive(T) -> T over the object's age
    Snapshot,        // snapshot(x) -> x, evaluated once at creation
    Prev,            // prev(x) -> x at the previous update
    Random,          // rand()/nrand() -> float, rand3() -> vec3, …
    Neighbours,      // near_sum(type, radius, term) -> term's type, near_count(type, radius) -> float
                     // (checked by frontend/check_near.cpp: its first argument is a type, its
                     // third a term over two objects)
};

struct BuiltinFunction {
    std::string_view name;
    int minArgs;
    int maxArgs;
    BuiltinRule rule;
    int width;                  // Construct and Random: the result's width
    std::string_view signature; // for notes: "clamp(x: T, lo: T|float, hi: T|float) -> T"
    std::optional<core::Op> op = std::nullopt;  // the operation it is, where it is exactly one
};

std::span<const BuiltinFunction> builtinFunctions();
int findBuiltinFunction(std::string_view name);  // -1 when none
const BuiltinFunction& builtinFunction(int index);

// Functions whose value depends on an object's history: only in object equations.
bool isTemporal(BuiltinRule rule);

// Predefined constants: pi, tau, origin and the named colours.
struct BuiltinConstant {
    std::string_view name;
    Type type;
    float value[4];
};
std::span<const BuiltinConstant> builtinConstants();
int findBuiltinConstant(std::string_view name);  // -1 when none

// `instance.pos`, `instance.x`, …: what a program reads of the instance an object belongs
// to (core/instances.h): lanes [first, first + width) of record value `record`.
struct InstanceMember {
    std::string_view name;
    int record;
    int first;
    int width;
    std::string_view meaning;  // for hovers and notes
};
std::span<const InstanceMember> instanceMembers();
int findInstanceMember(std::string_view name);  // -1 when none
// The name of the built-in value whose members those are.
constexpr std::string_view kInstanceName = "instance";

// `age`, `time`, `dt`: names that always mean the same thing inside an object.
std::span<const std::string_view> builtinVariables();
bool isBuiltinVariable(std::string_view name);

// The attributes of objects and files: `@integrator(rk4)`, `@step(1/240)`, `@capacity(N)`.
struct BuiltinAttribute {
    std::string_view name;
    std::string_view signature;  // "@step(seconds)"
    std::string_view doc;
};
std::span<const BuiltinAttribute> builtinAttributes();
std::string_view attributeDoc(std::string_view name);  // "" for an unknown attribute

// The words of grammar/Psys.g4 (a test keeps the two in step).
std::span<const std::string_view> keywords();

// The integrators `@integrator(…)` accepts, and what one computes (docs/language.md's
// table in a sentence, with its order and its stability limit): "" for an unknown name.
std::span<const std::string_view> integratorNames();
std::string integratorDoc(std::string_view name);

// What the commands, a sprite's shapes, the blends and the named types are, in a sentence
// each: what an editor shows on hover and in signature help ("" for a word that is none).
std::string_view commandDoc(std::string_view keyword);  // point, sprite, streak, trail, kill, emit, notify, when, on, spawn
std::string_view shapeDoc(std::string_view shape);
std::string_view blendDoc(std::string_view blend);
std::string_view typeDoc(std::string_view type);
// A draw command's parameters as a call: "point(position: vec3, colour: vec4, size: float)"
// (the optional ones last: `required` in core::drawSignature says how many must be given).
Type drawParamType(const core::DrawParam& p);
std::string drawCallSignature(core::DrawKind kind);

}  // namespace psys
