// Every GPU hazard of the GLSL backend, decided by one rule (docs/gpu.md, "Hazards").
//
// A GPU runs commands asynchronously and keeps caches that GL does not keep coherent for
// writes made by shaders: what a dispatch stores into a buffer is not seen by a later
// texture fetch, vertex pull, copy or host map unless a glMemoryBarrier with the bit of
// that *reader* comes between (GL 4.5 §7.13.2). Writes made by GL commands themselves —
// a copy, an upload, a clear — are ordered with every later command by the GL, the host's
// reads (glGetNamedBufferSubData) among them: nothing reads through a mapping. llvmpipe finishes each dispatch before the call
// returns and has one cache, so a missing bit passes there and fails on a GPU: hence
// one table (below), every call site naming what it wrote and who may read it next, and
// a strict mode that turns every write into a full barrier and a glFinish.
#pragma once

#include <cstdint>

namespace psys::gpu {

// What wrote a buffer.
enum class Write : uint8_t {
    Dispatch,  // a compute shader's stores and atomics (storage blocks)
    Copy,      // glCopyNamedBufferSubData
    Upload,    // the host's data: glNamedBufferData with data, or a new store and a copy (sendThrough)
    Clear,     // glClearNamedBufferSubData
};

// Who may read it next: a set of these.
enum Reader : uint32_t {
    kStorageBlock = 1u << 0,   // a shader's storage block (SSBO)
    kBufferTexture = 1u << 1,  // a shader's texelFetch from a buffer texture
    kUniformBlock = 1u << 2,   // a shader's uniform block (UBO)
    kVertexPull = 1u << 3,     // vertex attributes (the viewer draws render columns)
    kCopy = 1u << 4,           // a copy, upload or clear of the buffer; the host's read (glGetNamedBufferSubData)
};

// Every reader a column may have: kernels read it in place (storage block or buffer
// texture), copies stage it and fill launch blocks, the host reads it back, the viewer
// draws it.
constexpr uint32_t kColumnReaders = kStorageBlock | kBufferTexture | kUniformBlock | kVertexPull | kCopy;

// The glMemoryBarrier bits a write needs before `readers` see it: none for the GL's own
// commands, one bit per reader after a dispatch.
uint32_t barrierBits(Write write, uint32_t readers);

// Issues what barrierBits says; in strict mode a full barrier and glFinish after every
// write instead.
void afterWrite(Write write, uint32_t readers);

// Strict mode: PSYS_GPU_STRICT=1 in the environment (read once), or set by a test.
bool strictMode();
void setStrictMode(bool on);

}  // namespace psys::gpu
