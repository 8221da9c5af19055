// The rate rule: what an emitter's update of `dt` ending at t1 asks of one rate emit site
// (and of a burst, below). Written once, over the host's doubles, for
// every memory's bookkeeping (Creation::emitInUpdate and Memory::emitAtRate); a device
// spells the same in its own language (gpu/gl_emission.cpp) and the differential tests
// hold the two together.
//
// Events fall where the accumulated rate crosses a whole number, so a stream is smooth
// within a step and a rate of 0.25/s emits at 4 s, 8 s, …: the first at
// (t1 − dt) + (1 − before)/rate, the next 1/rate apart, `count` objects each. A rate or
// count that is NaN, infinite or negative is invalid (it emits nothing, and is counted);
// counts past kMaxCount are clamped (and counted).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace psys::rt {

// The most objects one emission may ask for: counts and rates beyond it (1e30 from a
// kernel, a trigger's argument) are taken as this many and counted, so no count overflows.
constexpr double kMaxCount = 1e18;

// An emission count or rate from a kernel: NaN, infinite and negative values count as
// invalid and emit nothing.
inline double validCount(float x, uint64_t& invalid) {
    if (!std::isfinite(x) || x < 0) {
        ++invalid;
        return 0;
    }
    return x;
}

// A valid count as a whole number of objects, at most kMaxCount (a clamp is counted).
inline uint64_t wholeCount(double x, uint64_t& clamped) {
    x = std::floor(x);
    if (x > kMaxCount) {
        ++clamped;
        return static_cast<uint64_t>(kMaxCount);
    }
    return static_cast<uint64_t>(x);
}

// a += b, stopping at the largest uint64 rather than wrapping around (what emissions ask
// for, summed).
inline void addSaturating(uint64_t& a, uint64_t b) { a = b > UINT64_MAX - a ? UINT64_MAX : a + b; }

struct RateEmission {
    double accumulated = 0;  // events accumulated after the update, in [0, 1)
    uint64_t children = 0;   // objects asked for (0: none)
    uint64_t perEvent = 1;   // objects an event
    double firstTime = 0, spacing = 0;
    uint64_t invalid = 0, clamped = 0;  // for the stats
};

// `before`: the events accumulated before the update, in [0, 1).
inline RateEmission rateEmission(double before, float rate, float count, double dt, double t1) {
    RateEmission e;
    double r = validCount(rate, e.invalid);
    double size = validCount(count, e.invalid);
    double total = before + r * dt;
    // A whole number reached by adding up rounded rates (0.25 · 1/60, 240 times) counts as reached.
    double events = std::floor(total + 1e-9);
    e.accumulated = std::max(0.0, total - events);
    if (events < 1 || size < 1) return e;
    e.perEvent = wholeCount(size, e.clamped);  // counted when it is asked for
    e.firstTime = (t1 - dt) + (1.0 - before) / r;
    e.spacing = 1.0 / r;
    e.children = wholeCount(events * static_cast<double>(e.perEvent), e.clamped);
    return e;
}

// A burst: `count` objects at one time `at`, each an event of its own — an `on death` or
// `when` burst in an update (at t1: the update yields 0 where nothing died or fired), a
// burst at the emitter's creation (at its creation time).
inline RateEmission burst(float count, double at) {
    RateEmission e;
    double size = validCount(count, e.invalid);
    e.firstTime = at;
    if (size >= 1) e.children = wholeCount(size, e.clamped);
    return e;
}

}  // namespace psys::rt
