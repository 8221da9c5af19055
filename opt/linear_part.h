// The linear part of a derivative: writing an integral's derivative as f = c·y + r, where
// y is the integral and c does not depend on y (r may still: only the part of f that is
// linear in y is recognised). For `integrate(a − k·x)` in the equation of x, c = −k.
//
// Two consumers: the exponential method solves y' = c·y exactly over each step, and the
// stability check compares k·dt with an explicit method's limit. The coefficient is a
// small expression over values of the kernel it was found in; each consumer builds it
// where it needs it (at the start of the step, or in evaluation order).
#pragma once

#include <array>
#include <functional>
#include <optional>
#include <vector>

#include "ir/ir.h"

namespace psys::opt {

struct Coefficient {
    enum class Kind { One, Neg, Add, Sub, Mul, Div };
    Kind kind = Kind::One;
    ir::Type type;
    ir::ValueId factor = 0;          // Mul: factor·parts[0]; Div: parts[0]/factor (a value of the kernel)
    std::vector<Coefficient> parts;
};

// The coefficient of `integral` (an `integrate` instruction) in `derivative`, or none when
// the derivative has no part linear in it. `recur` is followed to its equation; `prev`
// too when `throughPrev` (the default method, where an integrand reads its own integral
// as the previous update's value).
std::optional<Coefficient> linearPart(const ir::Kernel& k, ir::ValueId derivative, ir::ValueId integral,
                                      bool throughPrev);

// Builds the coefficient in `to`, with `leaf` giving each factor's value there.
ir::ValueId build(const Coefficient& c, ir::Kernel& to, const std::function<ir::ValueId(ir::ValueId)>& leaf);

// Its value, when every factor is a constant of `k`.
std::optional<std::array<double, 4>> constantValue(const Coefficient& c, const ir::Kernel& k);

}  // namespace psys::opt
