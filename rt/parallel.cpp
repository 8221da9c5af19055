#include "rt/parallel.h"

#include <algorithm>

#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace psys::rt::detail {

struct Parallel::Arena {
    tbb::task_arena arena;
    // (More threads than TBB's workers and this one, the machine's cores, run on no more of
    // them, and TBB warns on stderr at each request: asked for as many as there are.)
    explicit Arena(unsigned threads)
        : arena(threads ? std::min(static_cast<int>(threads), tbb::info::default_concurrency())
                        : tbb::task_arena::automatic) {}
};

// The arena's threads asked for now, not by the first step with two chunks: starting them
// took 0.7 ms of that step (`psys_bench --hitches`: frame 9 of the fire at 10^5/s, against
// steps of 0.1 ms around it). Work for every slot makes TBB start its workers; this thread
// does not wait for them to arrive.
Parallel::Parallel(unsigned threads) : arena_(std::make_unique<Arena>(threads)) {
    int slots = arena_->arena.max_concurrency();
    if (slots > 1) arena_->arena.execute([&] { tbb::parallel_for(0, slots, [](int) {}); });
}
Parallel::~Parallel() = default;

void Parallel::forEach(size_t chunks, bool concurrent, core::FunctionRef<void(size_t)> chunk) {
    if (chunks > 1 && concurrent && arena_->arena.max_concurrency() > 1) {
        arena_->arena.execute([&] { tbb::parallel_for(size_t{0}, chunks, chunk); });
        return;
    }
    for (size_t c = 0; c < chunks; ++c) chunk(c);
}

}  // namespace psys::rt::detail
