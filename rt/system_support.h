// Small helpers the parts of System (rt/system*.cpp) share.
#pragma once

#include <chrono>
#include <cmath>
#include <cstdint>

#include "ir/value.h"

namespace psys::rt::detail {

using WallClock = std::chrono::steady_clock;
inline double seconds(WallClock::time_point a, WallClock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

// An emission count or rate from a kernel: NaN, infinite and negative values count as
// invalid and emit nothing.
inline double validCount(float x, uint64_t& invalid) {
    if (!std::isfinite(x) || x < 0) {
        ++invalid;
        return 0;
    }
    return x;
}

inline bool finite(const ir::Value& v, int width) {
    for (int i = 0; i < width; ++i)
        if (!std::isfinite(v.f[static_cast<size_t>(i)])) return false;
    return true;
}

}  // namespace psys::rt::detail
