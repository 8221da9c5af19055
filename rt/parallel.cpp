#include "rt/parallel.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace psys::rt::detail {

struct Parallel::Arena {
    tbb::task_arena arena;
    explicit Arena(unsigned threads) : arena(threads ? static_cast<int>(threads) : tbb::task_arena::automatic) {}
};

Parallel::Parallel(unsigned threads) : arena_(std::make_unique<Arena>(threads)) {}
Parallel::~Parallel() = default;

void Parallel::forEach(size_t chunks, bool concurrent, const std::function<void(size_t)>& chunk) {
    if (chunks > 1 && concurrent && arena_->arena.max_concurrency() > 1) {
        arena_->arena.execute([&] { tbb::parallel_for(size_t{0}, chunks, chunk); });
        return;
    }
    for (size_t c = 0; c < chunks; ++c) chunk(c);
}

}  // namespace psys::rt::detail
