// The integration methods `@integrator(…)` names: the front end checks the name, the IR
// carries the method as an object attribute, and opt/lower_temporal lowers it (the
// tableaux and closed forms are in opt/integrate_*.cpp; docs/language.md says what each
// computes, docs/accuracy.md what each costs and how accurate it is).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

namespace psys::core {

enum class Integrator : uint8_t { Euler, SemiImplicit, Midpoint, Rk2, Rk4, Exponential, Exact, Leapfrog, Bs3 };

constexpr std::array<std::string_view, 9> kIntegratorNames = {"euler", "semi_implicit", "midpoint", "rk2", "rk4",
                                                              "exponential", "exact", "leapfrog", "bs3"};

constexpr std::string_view integratorName(Integrator i) { return kIntegratorNames[static_cast<size_t>(i)]; }

constexpr std::optional<Integrator> integratorFromName(std::string_view name) {
    for (size_t i = 0; i < kIntegratorNames.size(); ++i)
        if (kIntegratorNames[i] == name) return static_cast<Integrator>(i);
    return std::nullopt;
}

// The time a @tolerance covers where it states none (seconds), and the tolerance bs3 holds
// an object to where it states none (metres, over that time).
constexpr double kToleranceSeconds = 10;
constexpr double kBs3Tolerance = 1e-3;

// The largest k·h for which a method keeps y' = −k·y from growing, h being the update's
// length: where the method's stability region meets the negative real axis. Euler, the
// semi-implicit step, both second-order Runge–Kutta methods and leapfrog stop at 2
// (leapfrog on a decay is Heun's method; on an oscillator x″ = −ω²x it is stable while
// ω·h < 2); the classical RK4 at 2.785293563405… (where its growth factor
// 1 − z + z²/2 − z³/6 + z⁴/24 comes back to 1). `exponential` and `exact` solve the
// linear decay exactly: no limit (0). `bs3` chooses its own steps, shrinking them where a
// decay needs it, within four tries an update: no fixed limit (its error control counts
// the updates it cannot hold, opt/integrate_adaptive.cpp).
constexpr double stabilityLimit(Integrator i) {
    switch (i) {
        case Integrator::Euler: case Integrator::SemiImplicit: case Integrator::Midpoint: case Integrator::Rk2:
        case Integrator::Leapfrog: return 2.0;
        case Integrator::Rk4: return 2.785293563405282;
        case Integrator::Exponential: case Integrator::Exact: case Integrator::Bs3: return 0.0;
    }
    return 0.0;
}

// How an object keeps its state, `@precision(…)`: floats, or pairs of floats (hi + lo, 48
// significant bits) computed in pair arithmetic (opt/precision_double.cpp).
enum class Precision : uint8_t { Float, Double };

constexpr std::string_view precisionName(Precision p) { return p == Precision::Double ? "double" : "float"; }

constexpr std::optional<Precision> precisionFromName(std::string_view name) {
    if (name == "float") return Precision::Float;
    if (name == "double") return Precision::Double;
    return std::nullopt;
}

}  // namespace psys::core
