// Stream compaction on the GPU: the rows of a flag column that are set, in row order,
// by prefix sums — deterministic (no order comes from atomics racing), so the same flags
// give the same list on any GPU, every time. The GLSL backend sends the host the list of
// rows an update killed instead of a flag per row.
//
// Three passes of 256 invocations a group, 4 rows an invocation: each group counts its
// set flags; one group scans the counts (each invocation a run of groups, then a scan of
// the 256 runs) and writes the total; each group scans its invocations' counts in shared
// memory and writes its rows at its offset, after the total. The host learns how many
// rows there are with the rows (GlslBackend reads them back with the launch's counts, at
// once or late: gpu/glsl_readback.cpp).
// The last pass may also zero a mask where the flags are set (a late launch's kills
// cleared in its pool's alive mask, rt::Backend::clearsKilled): it visits only the groups
// that have some, so the clearing costs no pass of its own over every row.
#pragma once

#include <cstddef>
#include "gpu/pass_timer.h"
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
    // Where set flags also zero a mask: mask[base + i], or mask[rows[offset + i]] where
    // `rows` (a GL buffer) is given.
    struct Clear {
        unsigned mask = 0;
        unsigned rows = 0;
        uint32_t base = 0, offset = 0;
    };
    // Into `out` (a GL buffer) from word `at`: how many of words[word + i], i < n, are
    // not 0, then those i in order (room for n + 1 words); and `clear`, where given. All
    // on the GPU: nothing waits.
    void compact(unsigned words, size_t word, size_t n, unsigned out, size_t at, const Clear* clear = nullptr);
    // The same for flags on the host, read back: the indices set.
    std::vector<uint32_t> flagged(std::span<const uint32_t> flags);
    PassTimer* timer = nullptr;  // its passes timed there ("compaction"), where set

private:
    unsigned count_ = 0, scan_ = 0, write_ = 0;  // programs
    unsigned groups_ = 0;                        // a buffer: per group its count, then its offset; the total
    size_t groupsCapacity_ = 0;
    unsigned params_ = 0;                        // the passes' parameters (gl_context.h, bindParams)
};

// Rows a work group of the compaction covers (256 invocations of 4 rows).
constexpr uint32_t kCompactGroup = 1024;

}  // namespace psys::gpu
