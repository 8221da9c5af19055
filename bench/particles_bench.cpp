// psys_bench: million particle-updates per second for the fountain, the fire and the
// fireworks, JIT-compiled, against the same effects written by hand (bench/hand_written.h)
// and the interpreter, with the memory-bandwidth bound measured in the same run (STREAM
// triad) and the JIT's compile time per sample. docs/performance.md shows a run and reads it.
//
// Each effect is run to its steady population (its extern scaled so that about N
// particles are alive), then `--frames` steps are timed one by one; the figure is live
// particles ÷ the median step time. A step is everything: updates, kills, emissions and
// creations. Drawing is timed apart, after as many more steps. `--memory` measures the
// peak memory of each effect alone, in a process of its own, against its pools' rows.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "codegen_llvm/llvm_backend.h"
#include "driver/compile.h"
#include "effects.h"
#include "gpu_figures.h"
#include "hand_written.h"
#include "interp/interpreter.h"
#include "rt/system.h"

using namespace psys;
using bench::Clock;
using bench::Effect;
using bench::median;
using bench::seconds;
using bench::stateBytes;

namespace {

// STREAM's triad, a[i] = b[i] + s·c[i] over arrays far larger than the caches: the
// bandwidth a streaming loop can reach, in bytes per second (3 floats per element).
double triad(unsigned threads, size_t elements) {
    std::vector<float> a(elements, 0), b(elements, 1), c(elements, 2);
    tbb::task_arena arena(threads ? static_cast<int>(threads) : tbb::task_arena::automatic);
    std::vector<double> times;
    for (int run = 0; run < 7; ++run) {
        auto start = Clock::now();
        arena.execute([&] {
            tbb::parallel_for(tbb::blocked_range<size_t>(0, elements, 1 << 16), [&](const tbb::blocked_range<size_t>& r) {
                float* __restrict pa = a.data();
                const float* __restrict pb = b.data();
                const float* __restrict pc = c.data();
                for (size_t i = r.begin(); i < r.end(); ++i) pa[i] = pb[i] + 3.0f * pc[i];
            });
        });
        times.push_back(seconds(start, Clock::now()));
    }
    volatile float sink = a[elements / 2];
    (void)sink;
    return 3.0 * sizeof(float) * static_cast<double>(elements) / *std::min_element(times.begin(), times.end());
}

struct Rate {
    double live = 0;
    double perSecond = 0;  // particle updates
};

// Times `frames` steps of each contender, in three rounds of blocks (A…B…C…, A…B…C…,
// …) so that the machine's drift hits them alike, while the idle spinning of one
// contender's threads does not slow the next one's first step: that step of every block
// is run but not timed. A figure is live ÷ median step.
std::vector<Rate> timeInterleaved(const std::vector<std::function<size_t()>>& steps, int frames) {
    constexpr int kRounds = 3;
    std::vector<std::vector<double>> times(steps.size());
    std::vector<double> live(steps.size(), 0);
    int perBlock = (frames + kRounds - 1) / kRounds;
    for (int round = 0; round < kRounds; ++round)
        for (size_t k = 0; k < steps.size(); ++k) {
            steps[k]();
            for (int f = 0; f < perBlock; ++f) {
                auto start = Clock::now();
                size_t n = steps[k]();
                times[k].push_back(seconds(start, Clock::now()));
                live[k] += static_cast<double>(n);
            }
        }
    std::vector<Rate> rates;
    for (size_t k = 0; k < steps.size(); ++k) {
        double mean = live[k] / static_cast<double>(times[k].size());
        rates.push_back({mean, mean / median(times[k])});
    }
    return rates;
}

// The resident memory of this process now, in bytes.
double residentBytes() {
    std::FILE* f = std::fopen("/proc/self/statm", "r");
    long pages = 0, resident = 0;
    if (f) {
        if (std::fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
        std::fclose(f);
    }
    return static_cast<double>(resident) * static_cast<double>(sysconf(_SC_PAGESIZE));
}

// One effect at one size, alone in this (forked) process: the memory before the first
// step (the program, LLVM, the compiled kernels: the fixed part), the peak after running
// to the steady population and drawing every step, and what the pools' rows account for.
std::string measureMemory(const Effect& effect, double particles, int frames) {
    codegen_llvm::LlvmBackend jit;
    double knob = bench::calibrate(effect, jit, particles);
    rt::SystemOptions options;
    options.capacity = static_cast<size_t>(particles * 1.5) + 1024;
    rt::System system(bench::compileEffect(effect.name, true), jit, options);
    float value = static_cast<float>(knob);
    system.setExtern(effect.knob, {&value, 1});
    auto type = static_cast<size_t>(system.typeIndex(effect.particles));
    double fixed = residentBytes();
    for (int f = 0; f < effect.warmFrames + frames; ++f) {
        system.step(1.0 / 60);
        system.draw(type);
    }
    struct rusage usage {};
    getrusage(RUSAGE_SELF, &usage);
    double peak = static_cast<double>(usage.ru_maxrss) * 1024;
    double rows = 0, rowBytes = 0, capacityBytes = 0;
    for (size_t t = 0; t < system.module().objects.size(); ++t) {
        double bytes = static_cast<double>(rt::Pool::rowBytes(system.module().objects[t]));
        rows += static_cast<double>(system.pool(t).rows()) * bytes;
        capacityBytes += static_cast<double>(system.pool(t).capacity()) * bytes;
        if (t == type) rowBytes = bytes;
    }
    double live = static_cast<double>(system.pool(type).live());
    return fmt::format("| {} | {:.2g} | {:.0f} | {:.0f} | {:.0f} | {:.0f} | {:.0f} | {:.2f} | {:.2f} |\n", effect.name, live,
                       rowBytes, capacityBytes / 1e6, rows / 1e6, fixed / 1e6, peak / 1e6, (peak - fixed) / capacityBytes,
                       (peak - fixed) / live);
}

// Each measurement in a child process of its own (forked before this process starts any
// thread), so that one's peak is not another's.
int memoryTable(const std::vector<std::string>& effects, const std::vector<double>& sizes, int frames) {
    std::cout << "| effect | live | row bytes | capacity × row bytes (MB) | rows used × row bytes (MB) | fixed (MB) | "
                 "peak RSS (MB) | (peak − fixed) / (capacity × row bytes) | (peak − fixed) / live (B) |\n"
                 "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    std::cout.flush();
    for (const std::string& name : effects)
        for (double particles : sizes) {
            const Effect* effect = bench::findEffect(name);
            if (!effect) return 2;
            int pipe[2];
            if (::pipe(pipe) != 0) return 1;
            pid_t child = fork();
            if (child == 0) {
                ::close(pipe[0]);
                std::string line = measureMemory(*effect, particles, frames);
                if (::write(pipe[1], line.data(), line.size()) < 0) _exit(1);
                _exit(0);
            }
            ::close(pipe[1]);
            std::string line;
            char buffer[512];
            ssize_t n;
            while ((n = ::read(pipe[0], buffer, sizeof buffer)) > 0) line.append(buffer, static_cast<size_t>(n));
            ::close(pipe[0]);
            int status = 0;
            waitpid(child, &status, 0);
            std::cout << line;
            std::cout.flush();
        }
    std::cout << "\n(row bytes: rt::Pool::rowBytes of the particles' type in the relaxed program the JIT runs, as psysc --stats prints after the slash; fixed: the process "
                 "before the first step; peak: getrusage's maximum resident set, with the system drawn every step)\n";
    return 0;
}

// Hitches: `effect` at its knob `value` from its first step, `frames` steps of 1/60 s timed
// one by one on every core, as a game runs it: the pools grow from nothing to the steady
// population while it runs. Prints the median, the 99th percentile and the worst step, the
// worst ÷ the median, the worst step ÷ the median of the 21 steps around it (a hitch, apart
// from the population's growth: the last steps update twice the median's objects), and
// the frames of the five worst.
// With `reserve` rows, each effect runs twice: as it is, then with its particles' rows
// reserved before the first step (rt::System::reserve, at most the capacity).
int hitchTable(const std::vector<std::string>& effects, double value, int frames, size_t capacity, size_t reserve,
               const std::string& json) {
    nlohmann::json rows = nlohmann::json::array();
    codegen_llvm::LlvmBackend jit;
    std::cout << fmt::format("Steps from the first, {} of 1/60 s each, on {} cores (extern at {:g}{}):\n\n", frames,
                             std::max(1u, std::thread::hardware_concurrency()), value,
                             capacity ? fmt::format(", capacity {}", capacity) : std::string(", the default capacity"))
              << "| effect | reserved | live at the end | median (ms) | 99th percentile (ms) | worst (ms) | worst ÷ median | "
                 "worst ÷ the median around it | the five worst (frame: ms) |\n|---|---:|---:|---:|---:|---:|---:|---:|---|\n";
    for (const std::string& name : effects)
        for (size_t reserved : reserve ? std::vector<size_t>{0, reserve} : std::vector<size_t>{0}) {
            const Effect* effect = bench::findEffect(name);
            if (!effect) return 2;
            rt::SystemOptions options;
            if (capacity) options.capacity = capacity;
            rt::System system(bench::compileEffect(name, true), jit, options);
            const auto particles = static_cast<size_t>(system.typeIndex(effect->particles));
            if (reserved) {
                reserved = std::min(reserved, system.pool(particles).capacity());
                if (auto error = system.reserve(particles, reserved)) {
                    std::cerr << *error << "\n";
                    return 1;
                }
        }
        float v = static_cast<float>(value);
        system.setExtern(effect->knob, {&v, 1});
        std::vector<double> times;
        for (int f = 0; f < frames; ++f) {
            auto start = Clock::now();
            system.step(1.0 / 60);
            times.push_back(seconds(start, Clock::now()) * 1e3);
            rows.push_back({{"effect", name}, {"reserved", reserved}, {"frame", f}, {"ms", times.back()},
                            {"live", system.pool(particles).live()}});
        }
        std::vector<size_t> order(times.size());
        for (size_t i = 0; i < order.size(); ++i) order[i] = i;
        std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return times[a] > times[b]; });
        std::vector<double> sorted = times;
        std::sort(sorted.begin(), sorted.end());
        std::string worst;
        for (size_t i = 0; i < std::min<size_t>(5, order.size()); ++i)
            worst += fmt::format("{}{}: {:.1f}", i ? ", " : "", order[i], times[order[i]]);
        double med = median(times), local = 0;
        for (size_t f = 0; f < times.size(); ++f) {
            size_t from = f < 10 ? 0 : f - 10, to = std::min(times.size(), f + 11);
            local = std::max(local, times[f] / median({times.begin() + static_cast<std::ptrdiff_t>(from),
                                                         times.begin() + static_cast<std::ptrdiff_t>(to)}));
        }
        std::cout << fmt::format("| {} | {} | {} | {:.2f} | {:.2f} | {:.2f} | {:.1f} | {:.1f} | {} |\n", name, reserved,
                                 system.pool(particles).live(), med, sorted[sorted.size() * 99 / 100], sorted.back(),
                                 sorted.back() / med, local, worst);
        std::cout.flush();
      }
    if (!json.empty() && !bench::writeJson(json, rows.dump(1), "psys_bench")) return 1;
    return 0;
}

// Prewarm: `seconds` of each effect at its knob `value` run ahead at once
// (rt::System::prewarm, steps of at most `longest`) against the same seconds stepped frame
// by frame at 1/60 s: the time each takes and the live particles after.
int prewarmTable(const std::vector<std::string>& effects, double value, double ahead, double longest) {
    codegen_llvm::LlvmBackend jit;
    std::cout << fmt::format("Prewarm: {:g} s at once in steps of at most {:g} s, against frames of 1/60 s (extern at "
                             "{:g}, {} cores):\n\n",
                             ahead, longest, value, std::max(1u, std::thread::hardware_concurrency()))
              << "| effect | prewarm (ms) | live after it | frames (ms) | live after them | frames ÷ prewarm |\n"
                 "|---|---:|---:|---:|---:|---:|\n";
    for (const std::string& name : effects) {
        const Effect* effect = bench::findEffect(name);
        if (!effect) return 2;
        double ms[2];
        size_t live[2];
        for (int way = 0; way < 2; ++way) {
            rt::System system(bench::compileEffect(name, true), jit);
            float v = static_cast<float>(value);
            system.setExtern(effect->knob, {&v, 1});
            system.step(0);  // (started: the first step's own work is not the prewarm's)
            auto start = Clock::now();
            if (way == 0) {
                if (auto error = system.prewarm(ahead, longest)) {
                    std::cerr << *error << "\n";
                    return 1;
                }
            } else {
                for (int f = 0; f < static_cast<int>(std::lround(ahead * 60)); ++f) system.step(1.0 / 60);
            }
            ms[way] = seconds(start, Clock::now()) * 1e3;
            live[way] = system.pool(static_cast<size_t>(system.typeIndex(effect->particles))).live();
        }
        std::cout << fmt::format("| {} | {:.1f} | {} | {:.1f} | {} | {:.1f} |\n", name, ms[0], live[0], ms[1], live[1],
                                 ms[1] / ms[0]);
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app("psys_bench: particle updates per second, JIT against hand-written C++ and the bandwidth bound");
    std::vector<double> sizes = {1e6, 1e7};
    int frames = 15;
    std::vector<std::string> effects = {"fountain", "fire", "fireworks"};
    double interpParticles = 1e5;
    size_t triadElements = size_t{1} << 26;
    bool skipCompile = false;
    bool gpuToo = false;
    bool memory = false;
    int compileRuns = 5;
    std::string json;
    bool hitches = false;
    double hitchValue = 1e5;
    size_t hitchCapacity = 0;
    app.add_option("--particles", sizes, "Live particles per effect (1e6 1e7)");
    app.add_option("--frames", frames, "Timed steps per measurement; the median counts (15)")->check(CLI::Range(5, 100000));
    app.add_option("--effects", effects, "fountain fire fireworks");
    app.add_option("--interp-particles", interpParticles, "Live particles for the interpreter (1e5)");
    app.add_option("--triad-elements", triadElements, "Floats per STREAM array (2^26)");
    app.add_flag("--skip-compile", skipCompile, "Leave out the compile times");
    app.add_flag("--gpu", gpuToo, "Also run the GLSL backend on each effect and size, beside the JIT");
    app.add_flag("--memory", memory, "Only the peak memory of each effect and size, each in a process of its own");
    app.add_option("--compile-runs", compileRuns, "Compiles per sample; the median counts (5)")->check(CLI::PositiveNumber);
    app.add_option("--json", json, "Also write the JIT's figures as JSON, a list of rows (bench/README.md names the fields)");
    app.add_flag("--hitches", hitches,
                 "Only the steps of each effect from its first, the pools growing as it runs: median, worst, worst ÷ median");
    app.add_option("--hitch-value", hitchValue, "--hitches: the effects' extern (1e5: the fire's rate per second)");
    app.add_option("--hitch-capacity", hitchCapacity, "--hitches: the pools' capacity (0: the default)");
    double prewarm = 0, prewarmStep = 0.1;
    app.add_option("--prewarm", prewarm, "time this many seconds of each effect run ahead at once (at --hitch-value)");
    app.add_option("--prewarm-step", prewarmStep, "--prewarm: the longest step");
    size_t hitchReserve = 0;
    app.add_option("--hitch-reserve", hitchReserve,
                   "--hitches: also run each effect with this many particle rows reserved before its first step");
    CLI11_PARSE(app, argc, argv);
    if (memory) return memoryTable(effects, sizes, frames);
    if (hitches) return hitchTable(effects, hitchValue, frames, hitchCapacity, hitchReserve, json);
    if (prewarm > 0) return prewarmTable(effects, hitchValue, prewarm, prewarmStep);

    unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    codegen_llvm::LlvmBackend jit;
    std::cout << fmt::format("# psys_bench on {} ({} cores), {} timed steps per figure (median)\n\n", jit.report().target, cores,
                             frames);
    double bandwidth1 = triad(1, triadElements), bandwidthAll = triad(0, triadElements);
    std::cout << fmt::format("STREAM triad: {:.1f} GB/s on 1 thread, {:.1f} GB/s on {} threads\n\n", bandwidth1 / 1e9,
                             bandwidthAll / 1e9, cores);

    std::string breakdown, scaling;
    nlohmann::json rows = nlohmann::json::array();
    std::map<std::pair<std::string, double>, Rate> jitAllCores;  // for --gpu
    std::cout << "| effect | live | threads | psys JIT | hand SoA | hand AoS | JIT / SoA | JIT / AoS | bound | JIT / bound |\n";
    std::cout << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const std::string& name : effects) {
        const Effect* effect = bench::findEffect(name);
        if (!effect) {
            std::cerr << "psys_bench: no effect `" << name << "`\n";
            return 2;
        }
        for (double particles : sizes) {
            double knob = bench::calibrate(*effect, jit, particles);
            auto capacity = static_cast<size_t>(particles * 1.5) + 1024;
            rt::SystemOptions options;
            options.capacity = capacity;
            rt::System system(bench::compileEffect(name, true), jit, options);
            float value = static_cast<float>(knob);
            system.setExtern(effect->knob, {&value, 1});
            auto type = static_cast<size_t>(system.typeIndex(effect->particles));
            for (int f = 0; f < effect->warmFrames; ++f) system.step(1.0 / 60);
            auto soa = bench::makeHandWritten(name, true, knob, capacity);
            auto aos = bench::makeHandWritten(name, false, knob, capacity);
            for (int f = 0; f < effect->warmFrames; ++f) {
                soa->step(1.0f / 60);
                aos->step(1.0f / 60);
            }
            double bytes = stateBytes(system.module().objects[type]);  // of the relaxed program the JIT runs
            double oneThread = 0;  // the JIT's updates a second on 1 thread (for the scaling)
            for (unsigned threads : {1u, cores}) {
                system.setThreads(threads);
                soa->setThreads(threads);
                aos->setThreads(threads);
                rt::Stats before = system.stats();
                auto rates = timeInterleaved(
                    {[&] {
                         system.step(1.0 / 60);
                         return system.pool(type).live();
                     },
                     [&] {
                         soa->step(1.0f / 60);
                         return soa->live();
                     },
                     [&] {
                         aos->step(1.0f / 60);
                         return aos->live();
                     }},
                    frames);
                rt::Stats after = system.stats();
                Rate j = rates[0], s = rates[1], a = rates[2];
                if (threads == cores) jitAllCores[{name, particles}] = j;
                double steps = static_cast<double>(after.steps - before.steps);
                double created = 0;
                for (size_t t = 0; t < after.types.size(); ++t)
                    created += static_cast<double>(after.types[t].created - before.types[t].created);
                // Drawing (the hand-written code draws nothing): what a viewer or --dump
                // consumes after each step, the render columns marked. A host that draws
                // every step has the step draw as it goes (rt/system_draw.h), so drawing
                // costs what a step and a draw take together beyond a step alone; the two are
                // timed interleaved, and what draw() itself takes is apart.
                auto drawing = timeInterleaved({[&] {
                                                    system.step(1.0 / 60);
                                                    return system.pool(type).live();
                                                },
                                                [&] {
                                                    system.step(1.0 / 60);
                                                    system.draw(type);
                                                    return system.pool(type).live();
                                                }},
                                               frames);
                double stepMs = 1e3 * j.live / j.perSecond;
                double drawMs = 1e3 * (drawing[1].live / drawing[1].perSecond - drawing[0].live / drawing[0].perSecond);
                rt::Stats drawBefore = system.stats();  // draw() alone, after steps that drew as they went
                for (int f = 0; f < frames; ++f) {
                    system.step(1.0 / 60);
                    system.draw(type);
                }
                double inDrawMs = (system.stats().drawSeconds - drawBefore.drawSeconds) * 1e3 / frames;
                breakdown += fmt::format(
                    "| {} | {:.2g} | {} | {:.2f} | {:.2f} | {:.2f} | {:.0f} | {:.2f} | {:.2f} | {:.0f}% | {:.2g} / {:.2g} |\n",
                    name, j.live, threads, (after.loopSeconds - before.loopSeconds) * 1e3 / steps,
                    (after.emitSeconds - before.emitSeconds) * 1e3 / steps,
                    (after.createSeconds - before.createSeconds) * 1e3 / steps,
                    created > 0 ? (after.createSeconds - before.createSeconds) * 1e9 / created : 0.0, drawMs, inDrawMs,
                    100 * drawMs / stepMs, s.live, a.live);
                double bound = (threads == 1 ? bandwidth1 : bandwidthAll) / bytes;
                rows.push_back({{"effect", name},
                                {"particles", j.live},
                                {"threads", threads},
                                {"jit_mups", j.perSecond / 1e6},
                                {"soa_mups", s.perSecond / 1e6},
                                {"aos_mups", a.perSecond / 1e6},
                                {"jit_over_soa", j.perSecond / s.perSecond},
                                {"bound_mups", bound / 1e6},
                                {"step_ms", stepMs},
                                {"update_ms", (after.loopSeconds - before.loopSeconds) * 1e3 / steps},
                                {"kills_emissions_ms", (after.emitSeconds - before.emitSeconds) * 1e3 / steps},
                                {"creation_ms", (after.createSeconds - before.createSeconds) * 1e3 / steps},
                                {"created_per_step", created / steps},
                                {"creation_ns", created > 0 ? (after.createSeconds - before.createSeconds) * 1e9 / created : 0.0},
                                {"drawing_ms", drawMs},
                                {"drawing_share", drawMs / stepMs}});
                if (threads == 1) oneThread = j.perSecond;
                else
                    scaling += fmt::format("| {} | {:.2g} | {:.2f} | {:.2f} | {:.2f} |\n", name, j.live,
                                           j.perSecond / oneThread, bandwidthAll / bandwidth1,
                                           j.perSecond / oneThread / (bandwidthAll / bandwidth1));
                std::cout << fmt::format("| {} | {:.2g} | {} | {:.0f} | {:.0f} | {:.0f} | {:.2f} | {:.2f} | {:.0f} | {:.0f}% |\n",
                                         name, j.live, threads, j.perSecond / 1e6, s.perSecond / 1e6,
                                         a.perSecond / 1e6, j.perSecond / s.perSecond, j.perSecond / a.perSecond,
                                         bound / 1e6, 100 * j.perSecond / bound);
                std::cout.flush();
            }
        }
    }
    if (!json.empty() && !bench::writeJson(json, rows.dump(2), "psys_bench")) return 1;
    std::cout << "\n(million particle updates per second; bound: triad bandwidth ÷ the bytes psys's update loop "
                 "must move per particle (state read and written, kept parameters read))\n\n";
    std::cout << "Where psys's steps went (ms per step), what drawing every step adds to it (a step and a draw against "
                 "a step alone, timed interleaved; and of that, draw() itself), and the hand-written populations:\n\n"
                 "| effect | live | threads | update loops | kills and emissions | creation | creation (ns/object) | "
                 "drawing | in draw() | drawing / step | live SoA / AoS |\n"
                 "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n"
              << breakdown << "\n";
    if (cores > 1)
        std::cout << fmt::format("How the JIT's steps scale from 1 thread to {} beside the STREAM triad's own scaling:\n\n"
                                 "| effect | live | JIT {}t ÷ 1t | triad {}t ÷ 1t | JIT's ÷ triad's |\n|---|---:|---:|---:|---:|\n",
                                 cores, cores, cores)
                  << scaling << "\n";

    if (gpuToo) {
        auto gpu = bench::gpuBackend("psys_bench: --gpu");
        if (!gpu) return 1;
        std::cout << fmt::format("The GLSL backend on {} beside the JIT on {} cores (psys_gpu_bench has the passes):\n\n",
                                 gpu->report().target, cores)
                  << "| effect | live | JIT (M/s) | GLSL (M/s) | GLSL / JIT | GLSL update pass (ms) |\n|---|---:|---:|---:|---:|---:|\n";
        for (const std::string& name : effects)
            for (double particles : sizes) {
                bench::GpuFigures g = bench::measureGpu(*bench::findEffect(name), particles, frames, *gpu);
                Rate j = jitAllCores[{name, particles}];
                std::cout << fmt::format("| {} | {:.2g} | {:.0f} | {:.1f} | {:.3f} | {:.2f}{} |\n", name, g.live,
                                         j.perSecond / 1e6, g.perSecond / 1e6, g.perSecond / j.perSecond,
                                         g.updateMilliseconds, g.wallPasses ? " (wall)" : "");
                std::cout.flush();
            }
        if (gpu->report().target.find("llvmpipe") != std::string::npos)
            std::cout << "\n(llvmpipe runs the shaders on the CPU: its figures say the backend works, not how fast a GPU runs it)\n";
        std::cout << "\n";
    }

    // The interpreter, on fewer particles (its rate hardly depends on how many).
    std::cout << "| effect | live | interpreter (1 thread) | JIT (1 thread) | JIT / interpreter |\n|---|---:|---:|---:|---:|\n";
    for (const std::string& name : effects) {
        const Effect& effect = *bench::findEffect(name);
        double knob = bench::calibrate(effect, jit, interpParticles);
        interp::Interpreter interpreter;
        rt::SystemOptions options;
        options.threads = 1;
        rt::System slow(bench::compileEffect(name), interpreter, options), fast(bench::compileEffect(name, true), jit, options);
        float value = static_cast<float>(knob);
        slow.setExtern(effect.knob, {&value, 1});
        fast.setExtern(effect.knob, {&value, 1});
        auto type = static_cast<size_t>(slow.typeIndex(effect.particles));
        for (int f = 0; f < effect.warmFrames; ++f) {
            slow.step(1.0 / 60);
            fast.step(1.0 / 60);
        }
        auto rates = timeInterleaved({[&] {
                                          slow.step(1.0 / 60);
                                          return slow.pool(type).live();
                                      },
                                      [&] {
                                          fast.step(1.0 / 60);
                                          return fast.pool(type).live();
                                      }},
                                     frames);
        Rate i = rates[0], j = rates[1];
        std::cout << fmt::format("| {} | {:.2g} | {:.1f} | {:.0f} | {:.0f}× |\n", name, i.live, i.perSecond / 1e6,
                                 j.perSecond / 1e6, j.perSecond / i.perSecond);
    }

    if (skipCompile) return 0;
    // Compile time, parse → callable: front end, optimizer, and the JIT of every kernel
    // (a fresh backend each time, so nothing is cached); the median of --compile-runs.
    std::cout << "\n| sample | front end + optimizer (ms) | JIT (ms) | kernels | parse → callable (ms) |\n|---|---:|---:|---:|---:|\n";
    std::vector<std::filesystem::path> samples;
    for (auto& entry : std::filesystem::directory_iterator(PSYS_SAMPLES_DIR))
        if (entry.path().extension() == ".psys") samples.push_back(entry.path());
    std::sort(samples.begin(), samples.end());
    for (const auto& path : samples) {
        std::vector<double> front, total, jitTimes;
        size_t kernels = 0;
        for (int run = 0; run < compileRuns; ++run) {
            auto start = Clock::now();
            ir::Module module = bench::compileEffect(path.stem().string());
            auto compiled = Clock::now();
            codegen_llvm::LlvmBackend backend;
            rt::System system(std::move(module), backend);
            auto ready = Clock::now();
            front.push_back(seconds(start, compiled));
            total.push_back(seconds(start, ready));
            jitTimes.push_back(backend.report().compileSeconds);
            kernels = backend.report().kernels;
        }
        std::cout << fmt::format("| {} | {:.1f} | {:.1f} | {} | {:.1f} |\n", path.filename().string(), median(front) * 1e3,
                                 median(jitTimes) * 1e3, kernels, median(total) * 1e3);
    }
    return 0;
}
