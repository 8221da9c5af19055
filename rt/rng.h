// The random numbers on the host: core/hash.h's definition evaluated with plain integers,
// and the fixed object ids and draw indices the run-time keys draws with.
#pragma once

#include <cstdint>

#include "core/hash.h"

namespace psys::rt {

constexpr uint32_t pcgHash(uint32_t v) {
    core::HostAlgebra a;
    return core::pcgHash(a, v);
}

constexpr uint32_t drawBits(uint32_t seed, uint32_t object, uint32_t site, uint32_t draw, uint32_t component) {
    core::HostAlgebra a;
    return core::drawBits(a, seed, object, site, draw, component);
}

// Uniform in [0, 1): the top 24 bits, exactly representable in a float.
constexpr float uniform01(uint32_t bits) {
    core::HostAlgebra a;
    return core::unitInterval(a, bits);
}

// The draw index of evaluations made while an object is being created.
constexpr uint32_t kCreationDraw = 0xFFFFFFFFu;
// The object ids of the start of the system and of triggers (their draws are per child).
constexpr uint32_t kStartObject = 0xFFFFFFFEu;
constexpr uint32_t kTriggerObject = 0xFFFFFFFDu;

}  // namespace psys::rt
