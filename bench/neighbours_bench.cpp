// psys_neighbours_bench: the neighbour folds (docs/language.md, "Neighbours") per particle
// per step, on the JIT and the interpreter, against the same crowd written by hand
// (bench/hand_grid.cpp): n particles at random, about 32 within reach of each, one push
// and one count folded over them each step. The hand-written grid twice: walking the
// particles in their own order, and in the grid's (as the run-time does); the JIT's ratio
// is to the faster of the two. `--gpu`: the GLSL backend beside them (its
// fold's GPU time: psys_gpu_bench --neighbours, the figure a GPU machine gives).
#include <algorithm>
#include <iostream>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "codegen_llvm/llvm_backend.h"
#include "effects.h"
#include "interp/interpreter.h"
#include "neighbours.h"

using namespace psys;

int main(int argc, char** argv) {
    CLI::App app("psys_neighbours_bench: neighbour folds per particle, the JIT against a hand-written grid");
    std::vector<double> sizes = {1e5, 1e6};
    double neighbours = 32;
    int frames = 9;
    double interpParticles = 1e5;
    app.add_option("--particles", sizes, "Particles in the crowd (1e5 1e6)");
    app.add_option("--neighbours", neighbours, "Particles within reach of each, on average (32)");
    app.add_option("--frames", frames, "Timed steps per figure; the median counts (9)")->check(CLI::Range(3, 10000));
    app.add_option("--interp-particles", interpParticles, "The largest crowd the interpreter runs (1e5; 0: none)");
    CLI11_PARSE(app, argc, argv);

    unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    codegen_llvm::LlvmBackend jit;
    interp::Interpreter interpreter;
    std::cout << fmt::format("# psys_neighbours_bench on {} ({} cores), {} neighbours each, median of {} steps\n\n",
                             jit.report().target, cores, neighbours, frames);
    std::cout << "| particles | threads | hand-written, row order: fold ms | hand-written, cell order: fold ms | "
                 "JIT: fold ms | JIT / faster hand | JIT: ns per particle | JIT: M pairs/s | interpreter: fold ms |\n"
                 "|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for (double n : sizes) {
        for (unsigned threads : {1u, cores}) {
            size_t pairs = 0;
            auto handMs = [&](bench::HandWalk walk) {
                auto hand = bench::makeHandGrid(static_cast<size_t>(n),
                                                static_cast<float>(bench::crowdSide(n, neighbours)), threads, 1, walk);
                std::vector<double> times;
                for (int f = 0; f < frames + 3; ++f) {
                    auto start = bench::Clock::now();
                    hand->fold();
                    if (f >= 3) times.push_back(bench::seconds(start, bench::Clock::now()));
                    hand->update(1.0f / 60);
                }
                pairs = hand->pairs();
                return bench::median(times) * 1e3;
            };
            double rowsMs = handMs(bench::HandWalk::rows), cellsMs = handMs(bench::HandWalk::cells);
            bench::FoldFigures j = bench::measureCrowd(jit, n, neighbours, frames, threads);
            std::string interp = "";
            if (n <= interpParticles) {
                bench::FoldFigures i = bench::measureCrowd(interpreter, n, neighbours, 3, threads);
                interp = fmt::format("{:.1f}", i.foldSeconds * 1e3);
            }
            std::cout << fmt::format("| {:.0e} | {} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {:.1f} | {:.0f} | {} |\n", n,
                                     threads, rowsMs, cellsMs, j.foldSeconds * 1e3,
                                     j.foldSeconds * 1e3 / std::min(rowsMs, cellsMs), j.foldSeconds * 1e9 / j.live,
                                     static_cast<double>(pairs) / j.foldSeconds / 1e6, interp);
        }
    }
    return 0;
}
