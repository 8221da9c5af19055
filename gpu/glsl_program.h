// Internal to the GLSL backend (gpu/glsl_backend.cpp, gpu/glsl_children.cpp,
// gpu/glsl_readback.cpp): a compiled shader and what a launch of it carries and gives
// back; a late launch's read-back; the words of a launch block.
#pragma once

#include <bit>
#include <cstdint>
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
// then rows), the fence after the last, and once fetched what they said.
struct GlslBackend::Late {
    struct Part {
        size_t begin;  // the dispatch's first row
        size_t at;     // its region's first word
        bool kills;    // whether its kills follow its counts
    };
    std::vector<Part> parts;
    GLsync fence = nullptr;
    bool fetched = false;
    bool listed = false;  // its kills go to the launch's kill list (rt::RowsLaunch::killList), not here
    rt::RowsResult counts;
    std::vector<uint32_t> rows;
};

// The words every launch block starts with (count, clock, seed, draw), and 4-word values in it.
inline std::vector<uint32_t> blockHeader(const codegen_glsl::LaunchBlock& layout, size_t count, const rt::Clock& clock,
                                         uint32_t seed, uint32_t draw) {
    using codegen_glsl::LaunchBlock;
    std::vector<uint32_t> block(layout.words + 4, 0);
    block[LaunchBlock::kCount] = static_cast<uint32_t>(count);
    auto now = std::bit_cast<uint64_t>(clock.nowValue);
    block[LaunchBlock::kNow] = static_cast<uint32_t>(now);
    block[LaunchBlock::kNow + 1] = static_cast<uint32_t>(now >> 32);
    block[LaunchBlock::kDt] = std::bit_cast<uint32_t>(clock.dtValue);
    block[LaunchBlock::kFirst] = clock.first ? 1 : 0;
    block[LaunchBlock::kSeed] = seed;
    block[LaunchBlock::kDraw] = draw;
    return block;
}

inline void putValue(std::vector<uint32_t>& block, uint32_t word, const rt::Value& v) {
    for (size_t c = 0; c < 4; ++c) block[word + c] = std::bit_cast<uint32_t>(v.f[c]);
}

}  // namespace psys::gpu
