// What the particle benchmarks share (psys_bench, the JIT against hand-written C++;
// psys_gpu_bench, the GLSL backend alone): the effects, compiling them, finding the extern
// value that keeps N particles alive, and the bytes an update must move per particle.
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include "ir/ir.h"
#include "rt/backend.h"

namespace psys::bench {

using Clock = std::chrono::steady_clock;
inline double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }
double median(std::vector<double> v);

// What an effect is: its sample, the extern that sets its size, the object type that
// holds its particles, and how long it takes to reach its steady population.
struct Effect {
    std::string name;
    std::string knob;
    std::string particles;
    int warmFrames;
};

extern const std::vector<Effect> kEffects;
// Null when there is no effect of that name.
const Effect* findEffect(const std::string& name);

// The samples' folder: the source tree's, or where the environment's PSYS_SAMPLES_DIR
// says (a GPU bundle carries them beside its binaries: scripts/gpu-bundle.sh).
std::string samplesDir();

// The effect's sample, compiled (exits with the diagnostics if it does not compile);
// `relaxed`: with the optimizer's relaxed rewrites, as fast maths on the JIT compiles
// (host::BackendChoice::relaxesMaths).
ir::Module compileEffect(const std::string& name, bool relaxed = false);

// The extern value that keeps about `particles` alive: populations are proportional to
// it, so one short run at a small value on `backend` tells.
double calibrate(const Effect& e, rt::Backend& backend, double particles);

// Bytes the pool's update loop must read and write per particle: every state slot read
// and written, every kept parameter read.
double stateBytes(const ir::Object& o);

// Writes a bench's rows (a JSON array) to `path`; false, with the reason on stderr under
// `program`'s name, when it cannot.
bool writeJson(const std::string& path, const std::string& rows, const char* program);

}  // namespace psys::bench
