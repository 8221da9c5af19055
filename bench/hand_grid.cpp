// The crowd of bench/neighbours.h written by hand, the reference the neighbour folds are
// measured against: what a programmer would write for this one effect — positions and
// velocities as arrays, a grid of hashed cells rebuilt by a counting sort (the positions
// copied in bucket order, so the inner loop reads them in a row), the 27 cells around
// each particle, the push and the count in one pass over every thread. Compiled like
// hand_written.cpp (-O3 -march=native -ffast-math).
//
// Two walks: the particles in their own order (what one writes first), or in the grid's
// order with the 27 cells found once for the particles of a cell (what the run-time does:
// a cell's neighbours are read from memory once for all of them).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "neighbours.h"

namespace psys::bench {

namespace {

uint32_t mix(uint32_t v) {  // an integer hash (PCG's output step)
    uint32_t state = v * 747796405u + 2891336453u;
    uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

class Grid final : public HandGrid {
public:
    Grid(size_t n, float side, unsigned threads, unsigned seed, HandWalk walk)
        : n_(n), walk_(walk), arena_(threads ? static_cast<int>(threads) : tbb::task_arena::automatic) {
        std::mt19937 random(seed);
        std::uniform_real_distribution<float> u(0, side);
        for (auto* a : {&x_, &y_, &z_}) a->resize(n);
        for (auto* a : {&vx_, &vy_, &vz_, &px_, &py_, &pz_, &crowd_}) a->assign(n, 0);
        for (size_t i = 0; i < n; ++i) {
            x_[i] = u(random);
            y_[i] = u(random);
            z_[i] = u(random);
        }
        buckets_ = 64;
        while (buckets_ < 2 * n) buckets_ *= 2;
    }

    void fold() override {
        uint32_t mask = buckets_ - 1;
        auto cell = [](float p) { return static_cast<uint32_t>(static_cast<int32_t>(std::floor(p))); };
        auto bucket = [&](uint32_t cx, uint32_t cy, uint32_t cz) { return mix(mix(mix(cz) ^ cy) ^ cx) & mask; };
        std::vector<uint32_t>& of = of_;
        of.resize(n_);
        start_.assign(buckets_ + 1, 0);
        for (size_t i = 0; i < n_; ++i) {
            of[i] = bucket(cell(x_[i]), cell(y_[i]), cell(z_[i]));
            ++start_[of[i] + 1];
        }
        for (uint32_t b = 0; b < buckets_; ++b) start_[b + 1] += start_[b];
        sx_.resize(n_);
        sy_.resize(n_);
        sz_.resize(n_);
        sorted_.resize(n_);
        std::vector<uint32_t> next(start_.begin(), start_.end() - 1);
        for (size_t i = 0; i < n_; ++i) {
            uint32_t at = next[of[i]]++;
            sx_[at] = x_[i];
            sy_[at] = y_[i];
            sz_[at] = z_[i];
            sorted_[at] = static_cast<uint32_t>(i);
        }
        constexpr size_t kChunk = 1024;
        std::vector<size_t> pairs((n_ + kChunk - 1) / kChunk, 0);
        arena_.execute([&] {
            tbb::parallel_for(size_t{0}, pairs.size(), [&](size_t c) {
                size_t found = 0;
                uint32_t seen[27];
                int m = 0;
                uint32_t at[3] = {0, 0, 0};
                for (size_t k = c * kChunk; k < std::min(n_, (c + 1) * kChunk); ++k) {
                    size_t i = walk_ == HandWalk::cells ? sorted_[k] : k;
                    float px = x_[i], py = y_[i], pz = z_[i];
                    uint32_t cx = cell(px), cy = cell(py), cz = cell(pz);
                    if (walk_ == HandWalk::rows || m == 0 || cx != at[0] || cy != at[1] || cz != at[2]) {
                        at[0] = cx, at[1] = cy, at[2] = cz;
                        m = 0;
                        for (uint32_t dz = 0; dz < 3; ++dz)
                            for (uint32_t dy = 0; dy < 3; ++dy)
                                for (uint32_t dx = 0; dx < 3; ++dx) seen[m++] = bucket(cx + dx - 1, cy + dy - 1, cz + dz - 1);
                        std::sort(seen, seen + 27);
                        m = static_cast<int>(std::unique(seen, seen + 27) - seen);
                    }
                    float ax = 0, ay = 0, az = 0, count = 0;
                    for (int k = 0; k < m; ++k)
                        for (uint32_t j = start_[seen[k]]; j < start_[seen[k] + 1]; ++j) {
                            float dx = px - sx_[j], dy = py - sy_[j], dz = pz - sz_[j];
                            float d2 = dx * dx + dy * dy + dz * dz;
                            if (d2 > 1.0f || d2 == 0.0f) continue;  // (itself: the one at distance 0)
                            float w = 1.0f - std::sqrt(d2);
                            ax += dx * w;
                            ay += dy * w;
                            az += dz * w;
                            count += 1;
                        }
                    px_[i] = ax;
                    py_[i] = ay;
                    pz_[i] = az;
                    crowd_[i] = count;
                    found += static_cast<size_t>(count);
                }
                pairs[c] = found;
            });
        });
        pairs_ = 0;
        for (size_t p : pairs) pairs_ += p;
    }

    void update(float dt) override {
        for (size_t i = 0; i < n_; ++i) {
            vx_[i] = vx_[i] * 0.99f + px_[i] * dt;
            vy_[i] = vy_[i] * 0.99f + py_[i] * dt;
            vz_[i] = vz_[i] * 0.99f + pz_[i] * dt;
            x_[i] += vx_[i] * dt;
            y_[i] += vy_[i] * dt;
            z_[i] += vz_[i] * dt;
        }
    }

    size_t pairs() const override { return pairs_; }

private:
    size_t n_;
    HandWalk walk_;
    tbb::task_arena arena_;
    uint32_t buckets_ = 64;
    std::vector<float> x_, y_, z_, vx_, vy_, vz_, px_, py_, pz_, crowd_, sx_, sy_, sz_;
    std::vector<uint32_t> of_, start_, sorted_;
    size_t pairs_ = 0;
};

}  // namespace

std::unique_ptr<HandGrid> makeHandGrid(size_t n, float side, unsigned threads, unsigned seed, HandWalk walk) {
    return std::make_unique<Grid>(n, side, threads, seed, walk);
}

}  // namespace psys::bench
