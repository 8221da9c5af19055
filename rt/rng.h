// The counter-based random numbers every backend shares.
//
// A draw is a pure function of (seed, object id, call site, draw index, component): no
// generator state, so the interpreter, the JIT on any number of threads and the GPU draw
// the same numbers. The mixing function is the PCG-based integer hash of Jarzynski and
// Olano ("Hash Functions for GPU Rendering", 2020): 32-bit integer arithmetic only, so
// GLSL 4.3 computes it exactly as C++ does.
#pragma once

#include <cstdint>

namespace psys::rt {

constexpr uint32_t pcgHash(uint32_t v) {
    uint32_t state = v * 747796405u + 2891336453u;
    uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

constexpr uint32_t drawBits(uint32_t seed, uint32_t object, uint32_t site, uint32_t draw, uint32_t component) {
    uint32_t h = pcgHash(component ^ pcgHash(draw));
    h = pcgHash(h ^ site * 0x9E3779B9u);
    h = pcgHash(h ^ object);
    return pcgHash(h ^ seed);
}

// Uniform in [0, 1): the top 24 bits, exactly representable in a float.
constexpr float uniform01(uint32_t bits) { return static_cast<float>(bits >> 8) * (1.0f / 16777216.0f); }

// The draw index of evaluations made while an object is being created.
constexpr uint32_t kCreationDraw = 0xFFFFFFFFu;
// The object ids of the start of the system and of triggers (their draws are per child).
constexpr uint32_t kStartObject = 0xFFFFFFFEu;
constexpr uint32_t kTriggerObject = 0xFFFFFFFDu;

}  // namespace psys::rt
