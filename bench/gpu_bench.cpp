// psys_gpu_bench: the GLSL backend alone, on the GPU of the machine it runs on (or Mesa's
// llvmpipe where there is none): million particle updates per second for the fountain,
// the fire and the fireworks, the GPU time of each pass (GL timer queries), and the
// update pass's bytes per particle ÷ its time, to hold against the card's bandwidth.
//
// It links no LLVM: it is built to be copied, with the few shared libraries `ldd` lists,
// to a GPU machine that has none of this build (docs/gpu.md).
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "gpu_figures.h"
#include "gpu_samples.h"
#include "gpu_stress.h"
#include "host_cache.h"
#include "neighbours.h"
#include "interp/interpreter.h"

using namespace psys;

int main(int argc, char** argv) {
    CLI::App app("psys_gpu_bench: the GLSL backend's particle updates per second");
    std::vector<double> sizes = {1e6, 1e7};
    int frames = 15;
    std::vector<std::string> effects = {"fountain", "fire", "fireworks"};
    app.add_option("--particles", sizes, "Live particles per effect (1e6 1e7)");
    app.add_option("--frames", frames, "Timed steps per figure; the median counts (15)")->check(CLI::Range(3, 100000));
    app.add_option("--effects", effects, "fountain fire fireworks");
    // The host side's threshold is a trade a GPU decides (a read-back's round trip against
    // interpreting the rows): this is how to measure it there.
    size_t hostRows = gpu::GlslBackend::kHostRows;
    app.add_option("--host-rows", hostRows,
                   "Launches over at most this many rows run on the host when their columns are there (64; 0: none)");
    std::string rowsIn = "gpu";
    app.add_option("--rows", rowsIn,
                   "Where pools keep their rows: gpu (as the backend asks: on the GPU wherever a type can, emitters "
                   "whose emissions the GPU decides among them; the default), memory (the same, asked of the "
                   "run-time: SystemOptions::Rows::InMemory) or host (to compare)")
        ->check(CLI::IsMember({"gpu", "host", "memory"}));
    std::string json;
    app.add_option("--json", json, "Also write the figures as JSON, a list of rows (bench/README.md names the fields)");
    bool stress = false;
    app.add_flag("--stress", stress,
                 "The hostile shapes instead: burst chains and many types, against the interpreter (docs/gpu.md)");
    bool neighbours = false;
    app.add_flag("--neighbours", neighbours,
                 "Neighbour folds instead: a crowd of --particles (1e5 1e6 by default here), about 32 within reach of "
                 "each (bench/neighbours.h)");
    bool samples = false;
    app.add_flag("--samples", samples,
                 "Every sample instead (or --only's), each scaled to --particles live objects (1e5 1e7 by default here) "
                 "by starting its spawns many times: dispatches, waits and bytes between host and GPU a step");
    std::vector<std::string> only;
    app.add_option("--only", only, "With --samples: these samples only (their names, without .psys)");
    bool hostCache = false;
    app.add_flag("--host-cache", hostCache,
                 "What sharing the caches with a software GPU costs the host's thread: its fixed work between waits "
                 "for workers that stream 0 to 256 MB (bench/host_cache.h); no GL");
    CLI11_PARSE(app, argc, argv);
    if (stress) return bench::stressFigures(std::cout, frames);
    if (hostCache) return bench::hostCacheFigures(std::cout, 10 * frames);

    const rt::SystemOptions::Rows rowsOption = rowsIn == "host"     ? rt::SystemOptions::Rows::OnHost
                                               : rowsIn == "memory" ? rt::SystemOptions::Rows::InMemory
                                                                    : rt::SystemOptions::Rows::AsBackend;
    auto gpu = bench::gpuBackend("psys_gpu_bench", hostRows);  // the emitters (few rows) on the host
    if (!gpu) return 1;
    if (samples) {
        bench::SampleScale scale;
        if (app.count("--particles")) scale.sizes = sizes;
        if (app.count("--frames")) scale.frames = frames;
        scale.only = only;
        scale.rows = rowsOption;
        std::cout << fmt::format("# psys_gpu_bench --samples on {}, host side: {}\n", gpu->report().target,
                                 hostRows > 0 ? fmt::format("launches of at most {} rows", hostRows) : "off");
        return bench::sampleFigures(std::cout, *gpu, scale, json);
    }
    if (neighbours) {
        if (!app.count("--particles")) sizes = {1e5, 1e6};
        return bench::crowdFigures(std::cout, *gpu, sizes, frames);
    }
    std::string renderer = gpu->report().target;
    std::cout << fmt::format("# psys_gpu_bench on {}, {} timed steps per figure (median), host side: {}\n", renderer,
                             frames, hostRows > 0 ? fmt::format("launches of at most {} rows", hostRows) : "off");
    if (renderer.find("llvmpipe") != std::string::npos)
        std::cout << "# llvmpipe computes the shaders on the CPU: these figures say the backend works, not how fast a "
                     "GPU runs it\n";
    nlohmann::json rows = nlohmann::json::array();
    std::cout << "\n| effect | live | step (ms) | host CPU (ms) | M updates/s | update pass (ms) | other passes (ms, and how many a step) | state B/particle | "
                 "update pass GB/s | host↔GPU B/particle/step | staged B/particle/step | waits/step | late/step (stalled) | dispatches/step | host sleeps/step |\n|---|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const std::string& name : effects) {
        const bench::Effect* effect = bench::findEffect(name);
        if (!effect) {
            std::cerr << "psys_gpu_bench: no effect `" << name << "`\n";
            return 2;
        }
        for (double particles : sizes) {
            bench::GpuFigures f = bench::measureGpu(*effect, particles, frames, *gpu,
                                                    rowsOption);
            std::string others;
            for (const auto& [pass, ms] : f.passMilliseconds)
                if (pass != "update")
                    others += fmt::format("{}{} {:.2f} ({:.0f}×)", others.empty() ? "" : ", ", pass, ms, f.passLaunches[pass]);
            double gbs = f.updateMilliseconds > 0 ? f.stateBytes * f.live / (f.updateMilliseconds * 1e-3) / 1e9 : 0;
            double passes = 0;
            nlohmann::json byPass = nlohmann::json::object();
            for (const auto& [pass, ms] : f.passMilliseconds) {
                passes += ms;
                byPass[pass] = ms;
            }
            rows.push_back({{"effect", name}, {"particles", f.live}, {"step_ms", f.stepSeconds * 1e3},
                            {"passes_ms", passes}, {"passes", byPass}, {"passes_wall", f.wallPasses}, {"host_cpu_ms", f.hostCpuSeconds * 1e3},
                            {"mups", f.perSecond / 1e6}, {"update_ms", f.updateMilliseconds},
                            {"update_gbs", gbs}, {"state_bytes", f.stateBytes}, {"transfer_bytes", f.transferBytes},
                            {"staged_bytes", f.stagedBytes}, {"waits", f.waits}, {"late_reads", f.lateReads},
                            {"late_stalls", f.lateStalls}, {"dispatches", f.dispatches},
                            {"host_sleeps", f.hostSleeps}, {"rows", rowsIn}, {"renderer", renderer}});
            std::cout << fmt::format("| {} | {:.2g} | {:.2f} | {:.2f} | {:.1f} | {:.2f}{} | {} | {:.0f} | {:.1f} | {:.1f} | {:.1f} | {:.1f} | {:.1f} ({:.1f}) | {:.1f} | {:.1f} |\n", name,
                                     f.live, f.stepSeconds * 1e3, f.hostCpuSeconds * 1e3, f.perSecond / 1e6, f.updateMilliseconds,
                                     f.wallPasses ? " (wall)" : "", others,
                                     f.stateBytes, gbs, f.transferBytes, f.stagedBytes, f.waits, f.lateReads,
                                     f.lateStalls, f.dispatches, f.hostSleeps);
            std::cout.flush();
        }
    }
    if (!json.empty() && !bench::writeJson(json, rows.dump(2), "psys_gpu_bench")) return 1;
    std::cout << "\n(host CPU: the CPU time of the thread that steps, the GL driver's threads not counted; passes: GPU time from GL timer queries, or \"wall\": from a glFinish before the pass to one after, "
                 "where the GL's timer does not see compute work; state B/particle: what the update pass must read and "
                 "write; update pass GB/s: that ÷ the pass's time; staged: copied on the GPU into and out of launches' words, beyond what the shaders move; waits/step: read-backs the host waited for mid-step; late/step: read-backs taken when the run-time needed them (kills at the step's end), and in brackets those the GPU had not finished by then; dispatches/step: compute dispatches the host recorded, kernels and bookkeeping; host sleeps/step: times the host's thread blocked, on llvmpipe each dispatch among them — the same work costs its thread more CPU time when the software GPU's workers have streamed more through the caches it shares: --host-cache)\n";
    return 0;
}
