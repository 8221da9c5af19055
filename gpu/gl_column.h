// Internal to gpu/: one column of GlMemory — the host's copy, the GL buffer and which of
// them holds the value — for the files that implement GlMemory's operations
// (gl_memory.cpp, gl_parents.cpp).
#pragma once

#include <cstdint>
#include <vector>

#include <epoxy/gl.h>

#include "gpu/gl_memory.h"

namespace psys::gpu {

struct GlMemory::Column {
    rt::Elem elem = rt::Elem::F32;
    size_t rows = 0;
    std::vector<uint8_t> hostCopy;
    GLuint gl = 0;
    size_t glRows = 0;    // rows the GL buffer has room for (pools grow a row at a time: doubled)
    bool device = false;  // the value is the GL buffer's (the host copy is stale)
    size_t zeroFrom = 0;  // on the GPU: the GL buffer holds zeros from this row on
    bool live = false;
    // Rows the host scattered into it while it is on the GPU, not sent yet (each row's
    // words after it, in the order written): sent in one scatter when the GPU next uses
    // the column or the host reads it (GlMemory::flush).
    std::vector<uint32_t> pending;
    size_t pendingRows = 0;
    size_t words() const { return rows * wordsPerRow(elem); }
};

}  // namespace psys::gpu
