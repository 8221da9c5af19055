// Compile-time evaluation of constant expressions.
//
// Used where the front end must know a value to check it: extern defaults and ranges,
// `@step`, `@capacity`, constant emission rates and counts. Returns nullopt for anything
// that is not a constant (an extern, `age`, `rand()`, a user function call, …).
//
// Values are floats computed by core/lanes.h, the arithmetic every backend runs, so a
// constant checked here is the constant the program computes. The checker keeps the
// values it computes on the AST (ConstValue, frontend/ast.h) for lowering to read.
#pragma once

#include <string>

#include <array>
#include <optional>

#include "frontend/ast.h"

namespace psys {

using ast::ConstValue;

std::optional<ConstValue> evaluateConstant(const ast::Expr& expr);

// A constant's value as a message shows it: `inf`, `-inf`, `NaN` (of any sign), or the number.
std::string numberText(double v);

}  // namespace psys
