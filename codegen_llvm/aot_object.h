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
    std::string cpu;     // empty: the host's CPU (for the host's triple), else "generic"
};

struct AotObject {
    std::string bytes;               // the archive (.a)
    std::string triple, cpu;         // what it was compiled for
    size_t kernels = 0;              // functions in it
    std::vector<std::string> calls;  // the functions outside it that it calls (libm, libmvec)
};

// Compiles `module` (which must be what `irText` parses back to: the keys are computed from
// it) into an archive defining `symbol` (a psys_aot) and nothing else visible. Throws
// std::runtime_error with LLVM's message when the target is unknown or LLVM refuses.
AotObject buildAotObject(const ir::Module& module, const std::string& irText, const std::string& glsl, MathMode mode,
                         const AotTarget& target, const std::string& symbol);

}  // namespace psys::codegen_llvm
