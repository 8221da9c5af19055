// Internal to rt/: runs chunks of a launch on several threads. The only place the
// run-time uses TBB, so that no public header carries it.
#pragma once

#include <cstddef>
#include "core/function_ref.h"
#include <memory>

namespace psys::rt::detail {

// Rows of host bookkeeping a piece run on one thread (a few cache-sized pieces of each
// array): State::forRows' and the pools' (Pool::forPieces).
constexpr size_t kHostRows = 16384;

class Parallel {
public:
    explicit Parallel(unsigned threads);  // 0: every core
    ~Parallel();
    // chunk(c) for c in [0, chunks): on several threads when `concurrent` and there is more
    // than one chunk, else in order on this thread.
    void forEach(size_t chunks, bool concurrent, core::FunctionRef<void(size_t)> chunk);

private:
    struct Arena;
    std::unique_ptr<Arena> arena_;
};

}  // namespace psys::rt::detail
