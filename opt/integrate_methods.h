// The integration methods other than the default: each builds, with a StepBuilder, every
// integral's value at the end of the update (docs/language.md says what each computes).
//
//   euler, midpoint, rk2, rk4   explicit Runge–Kutta methods: stages re-evaluate the
//                               derivatives at instants inside the step (opt/integrate_methods.cpp)
//   leapfrog                    velocity Verlet: a half kick, a drift, a half kick
//                               (opt/integrate_methods.cpp)
//   exponential                 Euler's step with each integral's linear decay solved
//                               exactly over the step (opt/integrate_methods.cpp)
//   exact                       closed forms over the step (opt/integrate_exact.cpp)
//   bs3                         the Bogacki–Shampine 3(2) pair, each object's steps its own
//                               under error control (opt/integrate_adaptive.cpp)
#pragma once

#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/integrators.h"
#include "opt/integrate_step.h"
#include "opt/linear_part.h"
#include "opt/passes.h"

namespace psys::opt {

// euler, midpoint, rk2 (Heun's method) or rk4: the classical Butcher tableaux. With
// `exactWeights` (@precision(double)), a weight that is no float (rk4's 1/6) is a division,
// which the double-precision pass carries out in pairs; so is bs3's 2/9, 1/3, 4/9.
std::vector<ir::ValueId> rungeKutta(StepBuilder& b, core::Integrator method, bool exactWeights = false);

// Velocity Verlet (Störmer–Verlet, "kick-drift-kick"), second order, symplectic on a
// separable system (positions from velocities, velocities from forces of the positions).
// The integrals split in two: a *drift* reads, at the same instant, only integrals that are
// not drifts and is read by no drift (a position, integrated from a velocity); every other
// integral is *kicked* (a velocity). With K the kicked and D the drifts:
//   K½ = K + h/2·f_K(start)
//   D' = D + h·f_D(middle, K½)
//   K' = K½ + h/2·f_K(end, D', K + h·f_K(start)), summed as K + h/2·(f_K(start) + f_K(end))
// When f_K does not read K (forces of positions) this is velocity Verlet exactly; where it
// does (drag) the end's K is Euler's estimate, which keeps the order 2. A system with no
// drift (a decay, a spin) is Heun's method.
std::vector<ir::ValueId> leapfrog(StepBuilder& b);

// The Bogacki–Shampine 3(2) pair with error control, up to four attempted steps an update
// (the file's header says how): `stepSlot` is the object's f32 slot for the step to try
// next; a step is kept while its error estimate is at most tolerancePerSecond × its length.
std::vector<ir::ValueId> bogackiShampine(StepBuilder& b, int stepSlot, float tolerancePerSecond,
                                        bool exactWeights = false);

// Each integral y' = f with f = c·y + r (c its linear part, when it has one):
// y + dt·φ1(−c·dt)·f, all at the start of the step; Euler's step where there is no c.
// `coefficient` builds integral j's c at the start of the step.
std::vector<ir::ValueId> exponentialEuler(StepBuilder& b, const std::vector<bool>& hasLinearPart,
                                          const std::function<ir::ValueId(size_t)>& coefficient);

// Closed forms over the step, or an error at the integral that has none. `names`: the
// equation each integral is in, for the message.
std::optional<std::vector<ir::ValueId>> closedForm(StepBuilder& b, const std::string& object,
                                                   const std::vector<std::string>& names, PassErrors& errors);

// A decay rate k the compiler found in an integral's derivative (f = −k·y + …).
struct DecayRate {
    std::string equation;  // the equation the integral is in
    ir::Loc loc;           // the integral
    std::optional<std::array<double, 4>> constant;  // k, when it is a constant
    std::function<ir::ValueId()> build;             // k in the lowered kernel
};

// For a method with a stability limit (core::stabilityLimit): a warning for each constant
// rate beyond it at the object's step (@step, else 1/60 s), and the value of the
// `unstable` yield: whether k·dt is beyond the limit for any rate this update (none when
// no rate can be). `step`: the object's @step (0: none).
std::optional<ir::ValueId> stabilityCheck(ir::Kernel& to, const std::string& object, core::Integrator method,
                                          float step, const std::vector<DecayRate>& rates, PassErrors& errors);

}  // namespace psys::opt
