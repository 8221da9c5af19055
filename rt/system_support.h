// Small helpers the parts of System (rt/system*.cpp) share.
#pragma once

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "ir/value.h"
#include "rt/clock.h"
#include "rt/emission.h"

namespace psys::rt::detail {

using WallClock = std::chrono::steady_clock;
inline double seconds(WallClock::time_point a, WallClock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

inline bool finite(const ir::Value& v, int width) {
    for (int i = 0; i < width; ++i)
        if (!std::isfinite(v.f[static_cast<size_t>(i)])) return false;
    return true;
}

// out[row] = keep[row] && !(unless[row] && also[row]) over [begin, end), for flags that are
// 0 or 1; `unless` null: keep as it is; `also` null: unless alone. Eight rows at a time: a
// byte loop over every row of a pool costs as much as the render it feeds.
inline void maskRows(uint8_t* out, const uint8_t* keep, const uint8_t* unless, const uint8_t* also, size_t begin, size_t end) {
    auto word = [](const uint8_t* p, size_t row) {
        uint64_t w;
        std::memcpy(&w, p + row, sizeof w);
        return w;
    };
    size_t row = begin;
    for (; row + 8 <= end; row += 8) {
        uint64_t drop = unless ? word(unless, row) & (also ? word(also, row) : ~uint64_t{0}) : 0;
        uint64_t w = word(keep, row) & ~drop;
        std::memcpy(out + row, &w, sizeof w);
    }
    for (; row < end; ++row) out[row] = keep[row] && !(unless && unless[row] && (!also || also[row]));
}

// The rows of [begin, end) whose kill flag is set, in order (most objects live: eight
// flags are tested at a time).
inline void listKilled(const uint8_t* kill, size_t begin, size_t end, std::vector<uint32_t>& out) {
    out.clear();
    size_t row = begin;
    for (; row + 8 <= end; row += 8) {
        uint64_t flags;
        std::memcpy(&flags, kill + row, sizeof flags);
        if (!flags) continue;
        for (size_t r = row; r < row + 8; ++r)
            if (kill[r]) out.push_back(static_cast<uint32_t>(r));
    }
    for (; row < end; ++row)
        if (kill[row]) out.push_back(static_cast<uint32_t>(row));
}

}  // namespace psys::rt::detail
