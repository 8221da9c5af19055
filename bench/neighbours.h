// The neighbour-fold benchmark's shared parts (docs/performance.md, "Neighbour folds"): a
// crowd of n particles in a box sized so that each has about `neighbours` others within
// reach, each step one fold of a push and a count over them; its hand-written twin; and
// how a step's fold is timed.
#pragma once

#include <cstddef>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "ir/ir.h"
#include "rt/backend.h"

namespace psys::gpu {
class GlslBackend;
}

namespace psys::bench {

// The crowd, compiled: `n` particles at random in a cube whose side puts `neighbours`
// within the reach of 1 on average.
ir::Module crowdModule(double n, double neighbours);
double crowdSide(double n, double neighbours);

struct FoldFigures {
    double live = 0;
    double pairs = 0;          // neighbour pairs within reach, per step
    double stepSeconds = 0;    // median step
    double foldSeconds = 0;    // median of the step's neighbours phase (the host's wall time)
};
// Steps a crowd of `n` on `backend` (warm steps first), `frames` timed.
FoldFigures measureCrowd(rt::Backend& backend, double n, double neighbours, int frames, unsigned threads = 0);

// The GLSL backend's figures for crowds of `sizes` (psys_gpu_bench --neighbours): a step,
// the fold's passes on the GPU (timer queries), waits and bytes moved per step.
int crowdFigures(std::ostream& out, gpu::GlslBackend& gpu, const std::vector<double>& sizes, int frames);

// The same crowd written by hand: SoA arrays, a grid rebuilt each step by a counting sort
// of hashed cells, then per particle the 27 cells around it — the push and the count in
// one pass (threads: the particles split into chunks). fold() runs that pass and the
// grid; step() the fold and the update. `walk`: the particles walked in their own order,
// or in the grid's with a cell's 27 buckets found once for its particles.
class HandGrid {
public:
    virtual ~HandGrid() = default;
    virtual void fold() = 0;
    virtual void update(float dt) = 0;
    virtual size_t pairs() const = 0;  // of the last fold
};
enum class HandWalk { rows, cells };
std::unique_ptr<HandGrid> makeHandGrid(size_t n, float side, unsigned threads, unsigned seed, HandWalk walk);

}  // namespace psys::bench
