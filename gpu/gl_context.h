// An OpenGL 4.5 core context without a window: EGL's surfaceless platform (Mesa's
// llvmpipe renders it on the CPU where there is no GPU; the NVIDIA driver's EGL on a GPU
// machine). The GPU backend computes in one when no context is current; the viewer draws
// offscreen into one.
#pragma once

#include <initializer_list>
#include <memory>
#include <string>

namespace psys::gpu {

class HeadlessContext {
public:
    // Null, and `error` set, when no such context can be made. With `share`: a context
    // that shares its objects (programs, buffers), to be made current on another thread.
    static std::unique_ptr<HeadlessContext> open(std::string& error, const HeadlessContext* share = nullptr);
    ~HeadlessContext();
    HeadlessContext(const HeadlessContext&) = delete;
    HeadlessContext& operator=(const HeadlessContext&) = delete;
    // Makes it the calling thread's current context; release: none.
    bool makeCurrent();
    void release();

private:
    HeadlessContext() = default;
    void* display_ = nullptr;
    void* context_ = nullptr;
};

// Whether the calling thread has a current EGL context (the viewer's, for one).
bool contextCurrent();

// A thread that has made current a context sharing the objects of a GLSL backend's (the
// viewer's reloader, with its surface's worker context) says so while it is: the backend's
// prepare then compiles a plan's programs there, off the backend's thread.
class SharedContextScope {
public:
    SharedContextScope();
    ~SharedContextScope();
    SharedContextScope(const SharedContextScope&) = delete;
    SharedContextScope& operator=(const SharedContextScope&) = delete;
};
bool sharedContextCurrent();


// Throws std::runtime_error naming `what` when the GL could not give a buffer its storage
// (GL_OUT_OF_MEMORY): a buffer without storage would read zeros and drop writes.
void checkAllocation(const char* what, size_t bytes);

// Runs the bound compute program over `invocations` invocations, `groupSize` to a work group,
// the grid in x then y: GL promises only 65,535 groups in a dimension, so a 1-D grid stops
// at 4,194,240 invocations of 64. A shader finds its invocation with kInvocationIndex
// and returns past the count.
void dispatchInvocations(size_t invocations, unsigned groupSize);
inline constexpr const char* kInvocationIndex =
    "((gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x + gl_LocalInvocationID.x)";

// The parameters of a utility shader (scatter, gather, compaction, clearing killed rows):
// a uniform block at binding 1 (the kernels' launch block is at 0), `param(k)` in the
// shader, written before each dispatch. Not default-block uniforms set with
// glProgramUniform: zink over lavapipe keeps using the values of a program's first
// dispatch (a clearing of killed rows then cleared one row of a thousand), and a block the
// host writes is what the kernels already use everywhere.
inline constexpr const char* kParamsBlock =
    "layout(std140, binding = 1) uniform Params { uvec4 P[3]; };\n"
    "uint param(uint k) { return P[k >> 2u][k & 3u]; }\n";
// Writes up to 12 values into `buffer` (created on first use: the caller owns it) and
// binds it as the Params block.
void bindParams(unsigned& buffer, std::initializer_list<uint32_t> values);

// Writes `bytes` of `data` into `target` at `offset` through a new store of `staging`
// (created on first use: the caller owns it) and a copy on the GPU, not with
// glNamedBufferSubData into `target`: a buffer earlier commands may still use is never
// written by the host. The GL orders such a write after them; zink over lavapipe, with two
// backends' commands interleaved in one context, gave other values now and then where the
// host wrote launch words, counts and columns so (docs/gpu.md, "A second GL").
void sendThrough(unsigned& staging, unsigned target, size_t offset, size_t bytes, const void* data);

// "llvmpipe (LLVM 15.0.6, 256 bits), OpenGL 4.5 (Core Profile) Mesa 22.3.6", …
std::string rendererName();

}  // namespace psys::gpu
