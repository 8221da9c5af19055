// A generator of well-typed psys programs, in the spirit of Csmith and YARPGen: not random
// bytes but programs a user could write, drawn from a seed — types nested up to three
// deep reading their parents live and after death, rate and count emissions, bursts at
// creation, on an edge (`when`) and `on death`, triggers fired at random frames with
// random arguments, externs changed mid-run, `@capacity` small enough to drop, `@step`
// sub-steps, integrators, kills at random ages, folds and trails — and an edit of each
// (a term changed, an equation or a type added or removed, a parameter renamed) that a
// hot reload takes mid-run. The same seed gives the same case on any machine.
//
// What every backend must agree on exactly (objects, ids, rows) is decided by what the
// program computes exactly everywhere: the GLSL backend and the JIT in exact maths give
// the interpreter's bits for + − × ÷, comparisons, floor, fract, the random draws and
// the ages, but the GL rounds sin, exp, pow and sqrt its own way. So those functions
// appear only in what is drawn (colours, sizes), never in what decides a kill, an
// emission or a position. Fast maths (fused multiply-adds) moves the last bits of any
// sum of products: a case whose decisions read nothing but ages, constants and externs
// (Case::compareFast) is compared under fast maths too.
#pragma once

#include <cstdint>

#include "tools/progen/case.h"

namespace psys::progen {

Case generate(uint64_t seed);

}  // namespace psys::progen
