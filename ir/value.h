// One IR value at run time: up to four floats, a bool (f[0] != 0) or a u32.
#pragma once

#include <array>
#include <cstdint>

namespace psys::ir {

struct Value {
    std::array<float, 4> f{};
    uint32_t u = 0;
    bool truth() const { return f[0] != 0; }
    static Value scalar(float x) { return {{x, 0, 0, 0}, 0}; }
    static Value boolean(bool b) { return {{b ? 1.0f : 0.0f, 0, 0, 0}, 0}; }
};

}  // namespace psys::ir
