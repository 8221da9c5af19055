// An ahead-of-time build (`psysc build`): every kernel a system's launches need, compiled
// by LLVM for a target CPU, as a static archive: one member a kernel, and one with the
// table that names each kernel's code by its launch key (native/compiled_backend.h) and
// the system's IR, as the `psys_aot` a host opens with psys_open_aot (include/psys/psys.h).
// The kernels are the JIT's (kernel_functions.h), each in a module of its own optimized
// and generated as the JIT does it (optimize.h): a build computes the JIT's bits, in fast
// maths as in exact.
#pragma once

#include <string>
#include <vector>

#include "codegen_llvm/jit_options.h"
#include "ir/ir.h"

namespace psys::codegen_llvm {

struct AotTarget {
    std::string triple;  // empty: the host's
    // The CPUs to compile for, each a set of kernels; empty (or ""): the host's CPU (for the
    // host's triple), else "generic". "native": the host's.
    std::vector<std::string> cpus;
};

struct AotObject {
    std::string bytes;               // the archive (.a)
    std::string triple;              // what it was compiled for
    std::vector<std::string> cpus;   // in the archive's order: the most capable first
    size_t kernels = 0;              // functions in it (every CPU's)
    std::vector<std::string> calls;  // the functions outside it that it calls (libm, libmvec)
};

// The features psysc build records of a CPU's code and psys_open_aot checks the running
// CPU for (capi/aot.cpp): LLVM's names, each one the compiler may use.
extern const char* const kCheckedFeatures[];

// Compiles `module` (which must be what `irText` parses back to: the keys are computed from
// it) into an archive defining `symbol` (a psys_aot) and nothing else visible: its kernels
// for each CPU of `target`, and `glsl` (none where empty). Throws std::runtime_error with
// LLVM's message when the target is unknown or LLVM refuses.
AotObject buildAotObject(const ir::Module& module, const std::string& irText, const std::string& glsl, MathMode mode,
                         const AotTarget& target, const std::string& symbol);

}  // namespace psys::codegen_llvm
