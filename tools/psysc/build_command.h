// `psysc build FILE -o NAME`: a system compiled ahead of time into NAME.a (its kernels for
// a target CPU, its IR, its shaders: codegen_llvm/aot_object.h) and NAME.h (the psys_aot
// that names it, typed setters for its externs and triggers, its types' indices), for a
// host that links libpsys_runtime: no compiler, no LLVM (docs/embedding.md).
#pragma once

#include <optional>
#include <string>

#include "core/integrators.h"

namespace psys::tools {

struct BuildOptions {
    std::string file;
    std::string output;          // NAME: NAME.a and NAME.h are written
    std::string math = "fast";   // or "exact": the interpreter's bits
    std::string target;          // empty: the host's
    std::string cpu;             // CPUs, comma-separated (empty: the host's): a set of kernels each
    bool glsl = true;            // false (--no-glsl): the archive holds no shaders
    bool optimize = true;
    bool relaxed = false;
    std::optional<core::Integrator> integrator;
    double tolerance = 0;        // --tolerance: every object's without @tolerance (0: none)
    bool colour = false;
};

// Returns the process exit status: 0, 1 (errors in the program, or LLVM refused), 2 (bad options).
int buildSystem(const BuildOptions& options);

}  // namespace psys::tools
