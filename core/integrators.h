// The integration methods `@integrator(…)` names: the front end checks the name, the IR
// carries the method as an object attribute, and opt/lower_temporal lowers it.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

namespace psys::core {

enum class Integrator : uint8_t { Euler, SemiImplicit, Midpoint, Rk2, Rk4, Exact };

constexpr std::array<std::string_view, 6> kIntegratorNames = {"euler", "semi_implicit", "midpoint", "rk2", "rk4", "exact"};

constexpr std::string_view integratorName(Integrator i) { return kIntegratorNames[static_cast<size_t>(i)]; }

constexpr std::optional<Integrator> integratorFromName(std::string_view name) {
    for (size_t i = 0; i < kIntegratorNames.size(); ++i)
        if (kIntegratorNames[i] == name) return static_cast<Integrator>(i);
    return std::nullopt;
}

}  // namespace psys::core
