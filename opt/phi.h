// The φ functions of exponential integrators, built in IR: the one definition the
// exponential and exact methods share.
//
//   φ0(z) = e^−z,   φn(z) = (1/(n−1)! − φn−1(z)) / z,   so φ1(z) = (1 − e^−z)/z.
//
// They carry a linear decay y' = a − k·y over a step of length h exactly:
// y(h) = y + h·(a − k·y)·φ1(k·h), and ∫₀ᵗ s^(n−1)·φn−1(k·s) ds = tⁿ·φn(k·t) integrates
// what such a decay feeds. The recurrence cancels catastrophically for small z, so for
// |z| < 2 they are the Taylor series Σ (−z)^m/(m+n)! (17 terms: below float's rounding).
#pragma once

#include "ir/ir.h"

namespace psys::opt {

// φn(z), componentwise for a vector z.
ir::ValueId phi(ir::Kernel& k, int n, ir::ValueId z);

}  // namespace psys::opt
