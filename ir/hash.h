// A structural hash of IR: two kernels with the same instructions, operands, attributes,
// constants (by their bits) and yields hash alike, whatever their names and locations.
// The JIT caches compiled code by it (codegen_llvm/llvm_backend.cpp).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "ir/ir.h"

namespace psys::ir {

struct Hash128 {
    uint64_t low = 0, high = 0;
    bool operator==(const Hash128&) const = default;
    std::string hex() const;
};

// A streaming 128-bit hash (two independent 64-bit lanes of multiply–xorshift mixing).
class Hasher {
public:
    Hasher& add(uint64_t word);
    Hasher& add(std::string_view bytes);
    Hasher& add(const Hash128& h) { return add(h.low).add(h.high); }
    Hash128 finish() const;

private:
    uint64_t a_ = 0x9E3779B97F4A7C15ull, b_ = 0xC2B2AE3D27D4EB4Full;
    uint64_t count_ = 0;
};

Hash128 structuralHash(const Kernel& kernel);

struct Hash128Hasher {
    size_t operator()(const Hash128& h) const { return static_cast<size_t>(h.low ^ (h.high * 0x9E3779B97F4A7C15ull)); }
};

}  // namespace psys::ir
