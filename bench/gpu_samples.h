// psys_gpu_bench --samples: every sample at two or more populations, what a step costs
// the host on the GLSL backend — compute dispatches, waits for the GPU, bytes between host
// and GPU. Where the bookkeeping is the GPU's, these stay the same as the particles grow
// (docs/gpu.md, "What is not on the GPU yet"); where they grow, the sample names the types
// whose rows the host keeps.
//
// A sample is scaled by starting its `spawn`s K times (each copy an object of its own,
// with its own id and so its own random draws), K chosen from a run at K = 1: each
// `spawn` a burst of K at the start, not K lines of source (a file may hold at most a
// MiB, and a sample of one particle needs 10⁷ of them).
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "gpu/glsl_backend.h"
#include "ir/ir.h"
#include "rt/system.h"

namespace psys::bench {

struct SampleScale {
    std::vector<double> sizes = {1e5, 1e7};  // live objects, of every type together
    int frames = 5;                          // measured steps of 1/60 s, after the warm-up
    double warmSeconds = 3;                  // the warm-up, in steps of 1/20 s
    std::vector<std::string> only;           // the samples' names; empty: every sample
    rt::SystemOptions::Rows rows = rt::SystemOptions::Rows::AsBackend;  // where pools keep their rows
};

// Prints a table (and, with `json` non-empty, writes its rows there); 0, or 1 where a
// sample could not be compiled or run.
int sampleFigures(std::ostream& out, gpu::GlslBackend& gpu, const SampleScale& scale, const std::string& json);

// The module's `spawn`s each start `copies` objects (the start kernel's counts; its
// arguments, evaluated once, are every copy's: no sample's draws a random value).
void startTimes(ir::Module& module, size_t copies);

}  // namespace psys::bench
