#include "gpu/hazards.h"

#include <cstdlib>
#include <cstring>

#include <epoxy/gl.h>

namespace psys::gpu {

namespace {

// The table of docs/gpu.md: after a dispatch, the barrier bit of each reader.
struct ReaderBit {
    Reader reader;
    GLbitfield bit;
};
constexpr ReaderBit kAfterDispatch[] = {
    {kStorageBlock, GL_SHADER_STORAGE_BARRIER_BIT},
    {kBufferTexture, GL_TEXTURE_FETCH_BARRIER_BIT},
    {kUniformBlock, GL_UNIFORM_BARRIER_BIT},
    {kVertexPull, GL_VERTEX_ATTRIB_ARRAY_BARRIER_BIT},
    {kCopy, GL_BUFFER_UPDATE_BARRIER_BIT},
};

int& strict() {
    static int on = [] {
        const char* v = std::getenv("PSYS_GPU_STRICT");
        return v && *v && std::strcmp(v, "0") != 0 ? 1 : 0;
    }();
    return on;
}

}  // namespace

uint32_t barrierBits(Write write, uint32_t readers) {
    if (write != Write::Dispatch) return 0;  // the GL orders its own commands
    GLbitfield bits = 0;
    for (const ReaderBit& r : kAfterDispatch)
        if (readers & r.reader) bits |= r.bit;
    return bits;
}

void afterWrite(Write write, uint32_t readers) {
    if (strictMode()) {
        glMemoryBarrier(GL_ALL_BARRIER_BITS);
        glFinish();
        return;
    }
    if (GLbitfield bits = barrierBits(write, readers)) glMemoryBarrier(bits);
}

bool strictMode() { return strict() != 0; }
void setStrictMode(bool on) { strict() = on ? 1 : 0; }

}  // namespace psys::gpu
