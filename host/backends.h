// Choosing a backend by name: the one place the tools know which backends exist.
//   llvm    the LLVM ORC JIT (codegen_llvm/), fast or exact maths
//   interp  the reference interpreter (interp/)
//   glsl    GLSL compute shaders on OpenGL 4.5 (codegen_glsl/, gpu/): a GPU, or llvmpipe
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "host/settings.h"
#include "rt/backend.h"

namespace psys::host {

struct BackendChoice {
    std::string name = "llvm";
    std::string math = "fast";  // llvm: fast or exact
    // Fast maths also compiles with the optimizer's relaxed rewrites (docs/optimizer.md):
    // it gives up bit-exactness for speed anyway. A session decides this when it opens
    // and keeps it through reloads and backend switches, so one session runs one program.
    bool relaxesMaths() const { return name == "llvm" && math == "fast"; }
    // llvm: the folder of the JIT's cache of compiled kernels ("": none); unset: as
    // PSYS_JIT_CACHE says, else $XDG_CACHE_HOME/psys/jit or ~/.cache/psys/jit.
    std::optional<std::string> jitCache = std::nullopt;
};

// The backends this build has, the default first.
std::vector<std::string> backendNames();
// A new backend, or the message saying why not (an unknown name or maths mode).
Parsed<std::shared_ptr<rt::Backend>> makeBackend(const BackendChoice& choice);

}  // namespace psys::host
