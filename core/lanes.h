// What each componentwise operation computes on one lane, in float: the one definition of
// the arithmetic. The interpreter and constant folding (ir/evaluate), and the front end's
// constant evaluation all compute through these functions; each compiling backend emits
// its own code for them and the differential tests hold it to these results (bit for bit
// in exact maths).
//
// IEEE-754 single precision throughout: x/0 is ±Inf (NaN for 0/0), log(0) is −Inf,
// sqrt(−1) is NaN. min and max are IEEE 754-2019's minimumNumber and maximumNumber: a NaN
// operand gives the other operand, and −0 counts as below +0. Both are symmetric, so the
// optimizer may order their operands (they are commutative in core/ops.h) without changing
// a result; clamp and saturate are built from them.
#pragma once

#include <cmath>

#include "core/ops.h"

namespace psys::core {

// The degree ↔ radian factors radians() and degrees() multiply by, rounded to float once.
constexpr float kRadiansPerDegree = static_cast<float>(3.14159265358979323846 / 180);
constexpr float kDegreesPerRadian = static_cast<float>(180 / 3.14159265358979323846);

// A unary componentwise op on one lane.
inline float lane(Op op, float x) {
    switch (op) {
        case Op::Neg: return -x;
        case Op::Sin: return std::sin(x);
        case Op::Cos: return std::cos(x);
        case Op::Tan: return std::tan(x);
        case Op::Asin: return std::asin(x);
        case Op::Acos: return std::acos(x);
        case Op::Atan: return std::atan(x);
        case Op::Tanh: return std::tanh(x);
        case Op::Exp: return std::exp(x);
        case Op::Log: return std::log(x);
        case Op::Sqrt: return std::sqrt(x);
        case Op::Abs: return std::fabs(x);
        case Op::Sign: return x > 0 ? 1.0f : x < 0 ? -1.0f : 0.0f;
        case Op::Floor: return std::floor(x);
        case Op::Ceil: return std::ceil(x);
        case Op::Round: return std::nearbyint(x);
        case Op::Fract: return x - std::floor(x);
        default: return 0;
    }
}

// IEEE 754-2019 minimumNumber and maximumNumber (see the top of this file): each backend
// spells out this same choice of operand.
inline float minimumNumber(float x, float y) { return (std::isnan(x) || y < x || (y == x && std::signbit(y))) ? y : x; }
inline float maximumNumber(float x, float y) { return (std::isnan(x) || x < y || (y == x && !std::signbit(y))) ? y : x; }

// A binary componentwise op on one lane.
inline float lane(Op op, float x, float y) {
    switch (op) {
        case Op::Add: return x + y;
        case Op::Sub: return x - y;
        case Op::Mul: return x * y;
        case Op::Div: return x / y;
        case Op::Mod: return x - y * std::floor(x / y);  // floored, as GLSL's mod
        case Op::Min: return minimumNumber(x, y);
        case Op::Max: return maximumNumber(x, y);
        case Op::Step: return y < x ? 0.0f : 1.0f;     // step(edge = x, value = y)
        case Op::Atan2: return std::atan2(x, y);
        case Op::Pow: return std::pow(x, y);
        default: return 0;
    }
}

// A comparison of two floats (lt, le, gt, ge).
inline bool compare(Op op, float x, float y) {
    switch (op) {
        case Op::Lt: return x < y;
        case Op::Le: return x <= y;
        case Op::Gt: return x > y;
        case Op::Ge: return x >= y;
        default: return false;
    }
}

}  // namespace psys::core
