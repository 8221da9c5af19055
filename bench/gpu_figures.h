// The GLSL backend on one effect at one size: what psys_gpu_bench prints and psys_bench
// --gpu sets beside the JIT.
#pragma once

#include <map>
#include <memory>
#include <string>

#include "effects.h"
#include "gpu/glsl_backend.h"
#include "rt/system.h"

namespace psys::bench {

struct GpuFigures {
    double live = 0;
    double stepSeconds = 0;        // median wall time of a step (everything, host included)
    double hostCpuSeconds = 0;     // median CPU time of the host's thread in a step (CLOCK_THREAD_CPUTIME_ID:
                                   // the GL driver's own threads, llvmpipe's workers among them, not counted)
    double perSecond = 0;          // particle updates per second: live ÷ stepSeconds
    double updateMilliseconds = 0; // GPU time of the update pass per step (timer queries)
    std::map<std::string, double> passMilliseconds;  // every pass, per step
    std::map<std::string, double> passLaunches;      // every pass: the pieces of work timed, per step
    bool wallPasses = false;       // the passes' times are wall times (the GL's timer saw nothing)
    double stateBytes = 0;         // per particle, what the update pass must read and write
    double transferBytes = 0;      // per particle per step, between the host and the GPU
    double waits = 0;              // per step: times the host waited for a read-back from the GPU
    double lateReads = 0, lateStalls = 0;  // per step: read-backs taken at the step's end; of them, not ready
    double stagedBytes = 0;        // per particle per step, copied on the GPU into and out of launches' words
    double dispatches = 0;         // per step: compute dispatches the host recorded (kernels and bookkeeping)
    double hostSleeps = 0;         // per step: times the host's thread blocked (voluntary context switches:
                                   // on llvmpipe each dispatch, fence or mapped read it waits for)
};

// The GLSL backend as psysc and the viewer make it, its host side taking launches of at
// most `hostRows` rows (0: none); null, with the GL's reason printed after `who`, where
// there is no OpenGL 4.5.
std::unique_ptr<gpu::GlslBackend> gpuBackend(const char* who, size_t hostRows = gpu::GlslBackend::kHostRows);

// Runs `effect` to its steady population of about `particles` on `gpu`, then times `frames` steps.
// `rows`: where the pools of objects that only die keep their rows (rt::SystemOptions::rows).
GpuFigures measureGpu(const Effect& effect, double particles, int frames, gpu::GlslBackend& gpu,
                      rt::SystemOptions::Rows rows = rt::SystemOptions::Rows::AsBackend);

}  // namespace psys::bench
