// Stream compaction on the GPU: the rows of a flag column that are set, in row order,
// by prefix sums — deterministic (no order comes from atomics racing), so the same flags
// give the same list on any GPU, every time. The GLSL backend sends the host the list of
// rows an update killed instead of a flag per row.
//
// Three passes of 256 invocations a group: each group counts its set flags; one group
// scans the counts (each invocation a run of groups, then a scan of the 256 runs); each
// group scans its flags in shared memory and writes its rows at its offset.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace psys::gpu {

class Compactor {
public:
    Compactor();
    ~Compactor();
    Compactor(const Compactor&) = delete;
    Compactor& operator=(const Compactor&) = delete;
    // The indices i < n with words[word + i] != 0 (a GL buffer of 32-bit words), in
    // order; `set` is how many there are (known from the kernel's counter).
    std::vector<uint32_t> flagged(unsigned words, size_t word, size_t n, size_t set);
    // The same for flags on the host (uploaded first).
    std::vector<uint32_t> flagged(std::span<const uint32_t> flags);

private:
    unsigned count_ = 0, scan_ = 0, write_ = 0;  // programs
    unsigned groups_ = 0, list_ = 0;             // buffers
    size_t groupsCapacity_ = 0, listCapacity_ = 0;
};

constexpr uint32_t kCompactGroup = 256;

}  // namespace psys::gpu
