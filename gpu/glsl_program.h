// Internal to the GLSL backend (gpu/glsl_backend.cpp, gpu/glsl_readback.cpp): a compiled
// shader and what a launch of it carries and gives back; a late launch's read-back.
#pragma once

#include <string>
#include <vector>

#include <epoxy/gl.h>

#include "codegen_glsl/glsl_shaders.h"
#include "gpu/glsl_backend.h"

namespace psys::gpu {

struct GlslBackend::Program {
    unsigned program = 0;  // a GL program
    codegen_glsl::LaunchBlock block;
    rt::ColumnLayout layout;
    std::vector<int> resident, returned;  // the table columns the kernel writes (writtenColumns)
    std::vector<int> direct;              // bound in place (codegen_glsl::directColumns): not staged, not adopted
    std::vector<bool> inPlace;            // per table column, the mask last: whether it is in `direct`
    std::vector<bool> needed;             // the table columns a launch carries (the others are not touched)
    std::string pass;          // "update", "spawn", …: what timer queries add up under
    bool counts = false;       // whether the shader counts anything (kills, unstable rows, what is drawn)
};

// A late launch: where each of its dispatches left its counts (4 words) and kills (total,
// then rows), the fence after the last, and once settled what they said.
struct GlslBackend::Late {
    struct Part {
        size_t begin;  // the dispatch's first row
        size_t at;     // its region's first word
        bool kills;    // whether its kills follow its counts
    };
    std::vector<Part> parts;
    GLsync fence = nullptr;
    bool settled = false;
    bool listed = false;  // its kills go to the launch's kill list (rt::RowsLaunch::killList), not here
    rt::RowsResult counts;
    std::vector<uint32_t> rows;
};

}  // namespace psys::gpu
