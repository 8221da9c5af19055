#include "gpu_figures.h"

#include <sys/resource.h>
#include <time.h>

#include <iostream>

#include "interp/interpreter.h"

#include "rt/system.h"

namespace psys::bench {

std::unique_ptr<gpu::GlslBackend> gpuBackend(const char* who, size_t hostRows) {
    std::string error;
    auto gpu = gpu::GlslBackend::create(error);
    if (!gpu) {
        std::cerr << who << ": " << error << "\n";
        return nullptr;
    }
    if (hostRows > 0) gpu->setHostSide(std::make_unique<interp::Interpreter>(gpu->memory()), hostRows);
    return gpu;
}

namespace {

long threadSleeps() {
    rusage usage{};
    getrusage(RUSAGE_THREAD, &usage);
    return usage.ru_nvcsw;
}

}  // namespace

GpuFigures measureGpu(const Effect& effect, double particles, int frames, gpu::GlslBackend& gpu,
                      rt::SystemOptions::Rows rows) {
    double knob = calibrate(effect, gpu, particles);
    rt::SystemOptions options;
    options.rows = rows;
    options.capacity = static_cast<size_t>(particles * 1.5) + 1024;
    rt::System system(compileEffect(effect.name), gpu, options);
    float value = static_cast<float>(knob);
    system.setExtern(effect.knob, {&value, 1});
    auto type = static_cast<size_t>(system.typeIndex(effect.particles));
    for (int f = 0; f < effect.warmFrames; ++f) system.step(1.0 / 60);
    GpuFigures out;
    out.stateBytes = stateBytes(system.module().objects[type]);
    // Wall times with the GPU untimed (a timer query waits for its pass), then the passes.
    std::vector<double> times, cpu;
    auto threadSeconds = [] {
        timespec t{};
        clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
        return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
    };
    double live = 0;
    uint64_t transferred = gpu.transferredBytes(), waits = gpu.waits(), staged = gpu.stagedBytes();
    uint64_t lateReads = gpu.lateReads(), lateStalls = gpu.lateStalls(), dispatches = gpu.dispatches();
    long sleeps = threadSleeps();
    for (int f = 0; f < frames; ++f) {
        auto start = Clock::now();
        double cpuStart = threadSeconds();
        system.step(1.0 / 60);
        cpu.push_back(threadSeconds() - cpuStart);
        times.push_back(seconds(start, Clock::now()));
        live += static_cast<double>(system.pool(type).live());
    }
    out.live = live / frames;
    out.transferBytes = static_cast<double>(gpu.transferredBytes() - transferred) / frames / std::max(out.live, 1.0);
    out.waits = static_cast<double>(gpu.waits() - waits) / frames;
    out.lateReads = static_cast<double>(gpu.lateReads() - lateReads) / frames;
    out.lateStalls = static_cast<double>(gpu.lateStalls() - lateStalls) / frames;
    out.stagedBytes = static_cast<double>(gpu.stagedBytes() - staged) / frames / std::max(out.live, 1.0);
    out.dispatches = static_cast<double>(gpu.dispatches() - dispatches) / frames;
    out.hostSleeps = static_cast<double>(threadSleeps() - sleeps) / frames;
    out.stepSeconds = median(times);
    out.hostCpuSeconds = median(cpu);
    out.perSecond = out.live / out.stepSeconds;
    auto before = gpu.passTimes();
    gpu.timePasses(true);
    int timed = std::max(1, frames / 3);
    for (int f = 0; f < timed; ++f) system.step(1.0 / 60);
    gpu.timePasses(false);
    double gpuTotal = 0, wallTotal = 0;
    for (const auto& [pass, t] : gpu.passTimes()) {
        gpuTotal += t.milliseconds - (before.count(pass) ? before.at(pass).milliseconds : 0);
        wallTotal += t.wallMilliseconds - (before.count(pass) ? before.at(pass).wallMilliseconds : 0);
    }
    // Where the GL's timer sees (almost) nothing of the compute work, the wall times.
    out.wallPasses = gpuTotal < 0.01 * wallTotal;
    for (const auto& [pass, t] : gpu.passTimes()) {
        const auto* b = before.count(pass) ? &before.at(pass) : nullptr;
        double ms = out.wallPasses ? t.wallMilliseconds - (b ? b->wallMilliseconds : 0) : t.milliseconds - (b ? b->milliseconds : 0);
        out.passMilliseconds[pass] = ms / timed;
        out.passLaunches[pass] = static_cast<double>(t.launches - (b ? b->launches : 0)) / timed;
    }
    out.updateMilliseconds = out.passMilliseconds.count("update") ? out.passMilliseconds["update"] : 0;
    return out;
}

}  // namespace psys::bench
