// The counter-based random numbers every backend shares, written once.
//
// A draw is a pure function of (seed, object id, call site, draw index, component): no
// generator state, so the interpreter, the JIT on any number of threads and the GPU draw
// the same numbers. The mixing function is the PCG-based integer hash of Jarzynski and
// Olano ("Hash Functions for GPU Rendering", 2020): 32-bit integer arithmetic only, so
// GLSL computes it exactly as C++ does.
//
// The definition is generic over an *algebra*: a type that provides the operations the
// hash is made of on its own kind of values. The host instantiates it with plain integers
// (HostAlgebra, below; rt/rng.h), the LLVM backend with an IR builder, a GLSL emitter
// with text. So a backend does not restate the hash; it says how to add, multiply, shift
// and convert, and emits the hash from this definition.
//
// An algebra A provides:
//   using Int   (32-bit unsigned), using Float (32-bit float)
//   Int constant(uint32_t); Float floatConstant(float);
//   Int add(Int, Int), mul(Int, Int), bitXor(Int, Int), shiftRight(Int, Int)  (mod 2^32)
//   Float toFloat(Int)   (unsigned → float, exact below 2^24)
//   Float fmul(Float, Float), fsub(Float, Float)
//   Int bitAnd(Int, Int)  (only where a grid's buckets are computed)
//   Int wholeToInt(Float) (a float, clamped to [-2^31, 2^31 - 128] — NaN to -2^31 — and
//                          truncated, as the bits of a 32-bit two's complement integer)
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/ops.h"

namespace psys::core {

template <class A>
constexpr typename A::Int pcgHash(A& a, typename A::Int v) {
    auto state = a.add(a.mul(v, a.constant(747796405u)), a.constant(2891336453u));
    auto shift = a.add(a.shiftRight(state, a.constant(28u)), a.constant(4u));
    auto word = a.mul(a.bitXor(a.shiftRight(state, shift), state), a.constant(277803737u));
    return a.bitXor(a.shiftRight(word, a.constant(22u)), word);
}

// The bits of one component of one draw, from the hash of the draw index (the same for
// every component, so a backend computes it once per draw).
template <class A>
constexpr typename A::Int drawBitsFromDraw(A& a, typename A::Int seed, typename A::Int object, uint32_t site,
                                           typename A::Int drawHash, uint32_t component) {
    auto h = pcgHash(a, a.bitXor(a.constant(component), drawHash));
    h = pcgHash(a, a.bitXor(h, a.constant(site * 0x9E3779B9u)));
    h = pcgHash(a, a.bitXor(h, object));
    return pcgHash(a, a.bitXor(h, seed));
}

// The bits of one component of one draw.
template <class A>
constexpr typename A::Int drawBits(A& a, typename A::Int seed, typename A::Int object, uint32_t site,
                                   typename A::Int draw, uint32_t component) {
    return drawBitsFromDraw(a, seed, object, site, pcgHash(a, draw), component);
}

// Uniform in [0, 1): the top 24 bits, exactly representable in a float.
template <class A>
constexpr typename A::Float unitInterval(A& a, typename A::Int bits) {
    return a.fmul(a.toFloat(a.shiftRight(bits, a.constant(8u))), a.floatConstant(1.0f / 16777216.0f));
}

// One component of `rand` (in [0, 1)) or `nrand` (in [-1, 1)), from the draw's hash.
template <class A>
constexpr typename A::Float drawLaneFromDraw(A& a, Op op, typename A::Int seed, typename A::Int object, uint32_t site,
                                             typename A::Int drawHash, uint32_t component) {
    auto u = unitInterval(a, drawBitsFromDraw(a, seed, object, site, drawHash, component));
    if (op == Op::NRand) return a.fsub(a.fmul(u, a.floatConstant(2.0f)), a.floatConstant(1.0f));
    return u;
}

template <class A>
constexpr typename A::Float drawLane(A& a, Op op, typename A::Int seed, typename A::Int object, uint32_t site,
                                     typename A::Int draw, uint32_t component) {
    return drawLaneFromDraw(a, op, seed, object, site, pcgHash(a, draw), component);
}

// `hash(x)`: lane `lane` of the lattice hash of a point of whole-number components (the
// corners of a noise's lattice, std/noise.psys): uniform in [-1, 1), each lane a function
// of every component, the same for every seed and object (a field, not a draw). Integer
// arithmetic only, so every backend computes the same bits.
template <class A, class Floats>
constexpr typename A::Float latticeLane(A& a, const Floats& x, int width, uint32_t lane) {
    auto h = a.constant(0x811C9DC5u);
    for (int c = 0; c < width; ++c) h = pcgHash(a, a.bitXor(h, a.wholeToInt(x[static_cast<size_t>(c)])));
    auto u = unitInterval(a, pcgHash(a, a.bitXor(h, a.constant(0x7F4A7C15u + lane * 0x9E3779B9u))));
    return a.fsub(a.fmul(u, a.floatConstant(2.0f)), a.floatConstant(1.0f));
}

// The neighbour grid's bucket of a cell (rt/neighbours.cpp): the cell's three whole
// coordinates hashed, `mask` + 1 buckets (a power of two). Several cells may share a
// bucket: a fold measures every candidate's distance anyway. The algebra needs bitAnd.
template <class A>
constexpr typename A::Int cellBucket(A& a, typename A::Int x, typename A::Int y, typename A::Int z, typename A::Int mask) {
    auto h = pcgHash(a, a.bitXor(z, a.constant(0x2545F491u)));
    h = pcgHash(a, a.bitXor(h, y));
    return a.bitAnd(pcgHash(a, a.bitXor(h, x)), mask);
}

// A grid's buckets for `rows` objects: a power of two, at least 64 and twice the rows
// (up to 2^30), so that a bucket holds few cells' objects.
constexpr uint32_t gridBuckets(size_t rows) {
    uint32_t buckets = 64;
    while (buckets < 2 * rows && buckets < (1u << 30)) buckets *= 2;
    return buckets;
}

// A grid's cell is the radius and this much wider, so that no rounding in computing a
// cell hides a pair at the radius from the 27 cells around an object.
inline constexpr float kCellMargin = 1.0f + 1.0f / 1024;

// The algebra of plain host integers and floats.
struct HostAlgebra {
    using Int = uint32_t;
    using Float = float;
    static constexpr Int constant(uint32_t x) { return x; }
    static constexpr Float floatConstant(float x) { return x; }
    static constexpr Int add(Int x, Int y) { return x + y; }
    static constexpr Int mul(Int x, Int y) { return x * y; }
    static constexpr Int bitXor(Int x, Int y) { return x ^ y; }
    static constexpr Int shiftRight(Int x, Int y) { return x >> y; }
    static constexpr Int bitAnd(Int x, Int y) { return x & y; }
    static constexpr Float toFloat(Int x) { return static_cast<float>(x); }
    static constexpr Float fmul(Float x, Float y) { return x * y; }
    static constexpr Float fsub(Float x, Float y) { return x - y; }
    static constexpr Int wholeToInt(Float x) {
        Float clamped = x >= -2147483648.0f ? (x <= 2147483520.0f ? x : 2147483520.0f) : -2147483648.0f;
        return static_cast<uint32_t>(static_cast<int32_t>(clamped));
    }
};

}  // namespace psys::core
