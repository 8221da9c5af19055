// The allocation rule: which row the k-th object a pool creates in a step takes. Written
// once, used by every backend's bookkeeping (Pool::allocate), so that the same seed gives
// the same rows on the interpreter, the JIT at any thread count and the GPU.
//
// Rows freed go on a stack, in the order their objects were freed (Pool::release); the
// k-th new object of a batch takes stack[top − 1 − k] while the stack lasts, then the rows
// past the high-water mark in order: highWater + (k − top). Each row depends only on k,
// so a batch's rows are computed at once (a prefix sum of the batch sizes gives k on a
// device), and objects past the pool's capacity are those with k ≥ room().
#pragma once

#include <cstddef>
#include <cstdint>

namespace psys::rt {

struct FreeRows {
    const uint32_t* stack = nullptr;  // rows freed, the last freed at the top
    size_t top = 0;                   // rows on the stack
    size_t highWater = 0;             // rows ever used: the next new row
    size_t capacity = 0;
    // How many objects may still be created.
    size_t room() const { return top + (capacity > highWater ? capacity - highWater : 0); }
    // The row of the k-th new object, k < room().
    uint32_t row(size_t k) const { return static_cast<uint32_t>(k < top ? stack[top - 1 - k] : highWater + (k - top)); }
};

// The creation time of the k-th object of a run whose events, `perEvent` objects each,
// are `spacing` apart from `firstTime` (Creation::Run; a device computes the same from
// rt::ObjectRuns). The product and the sum rounded each on its own (no fused multiply-add:
// -ffp-contract=off here, `precise` in GLSL).
inline double eventTime(double firstTime, uint64_t k, uint64_t perEvent, double spacing) {
    return firstTime + static_cast<double>(k / perEvent) * spacing;
}

}  // namespace psys::rt
