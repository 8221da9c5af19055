// The box around what is drawn, reduced on the GPU where the draw columns are
// (rt::Memory::bounds): each work group takes the least and greatest of its drawn rows'
// position components in shared memory, then one atomic per component folds them into six
// words, which come back to the host — 24 bytes, however many rows. The words hold the
// floats in an order-keeping encoding (negative: all bits flipped; else the sign bit set),
// so unsigned atomicMin and atomicMax order them as floats.
#include <epoxy/gl.h>

#include <array>
#include <bit>
#include <limits>
#include <string>

#include "gpu/gl_context.h"
#include "gpu/gl_memory.h"
#include "gpu/gl_programs.h"
#include "gpu/hazards.h"

namespace psys::gpu {

namespace {

const char* kBounds = R"(
layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer Visible { float visible[]; };
layout(std430, binding = 2) readonly buffer X { float px[]; };
layout(std430, binding = 3) readonly buffer Y { float py[]; };
layout(std430, binding = 4) readonly buffer Z { float pz[]; };
layout(std430, binding = 5) buffer Box { uint box[6]; };
shared vec3 low[256];
shared vec3 high[256];
uint ordered(float f) {
    uint u = floatBitsToUint(f);
    return (u & 0x80000000u) != 0u ? ~u : u | 0x80000000u;
}
void main() {
    uint i = INVOCATION, l = gl_LocalInvocationID.x;
    uint rows = param(0u), columns = param(1u);  // bit c: component c has a column
    vec3 constant = vec3(uintBitsToFloat(param(2u)), uintBitsToFloat(param(3u)), uintBitsToFloat(param(4u)));
    float inf = uintBitsToFloat(0x7f800000u);
    vec3 lo = vec3(inf), hi = vec3(-inf);
    if (i < rows && visible[i] == 1.0) {
        vec3 p = vec3((columns & 1u) != 0u ? px[i] : constant.x, (columns & 2u) != 0u ? py[i] : constant.y,
                      (columns & 4u) != 0u ? pz[i] : constant.z);
        lo = p;
        hi = p;
    }
    low[l] = lo;
    high[l] = hi;
    barrier();
    for (uint s = 128u; s > 0u; s >>= 1u) {
        if (l < s) {
            low[l] = min(low[l], low[l + s]);
            high[l] = max(high[l], high[l + s]);
        }
        barrier();
    }
    if (l == 0u && low[0].x <= high[0].x) {
        for (int c = 0; c < 3; ++c) {
            atomicMin(box[c], ordered(low[0][c]));
            atomicMax(box[3 + c], ordered(high[0][c]));
        }
    }
}
)";

uint32_t ordered(float f) {
    uint32_t u = std::bit_cast<uint32_t>(f);
    return (u & 0x80000000u) ? ~u : u | 0x80000000u;
}
float fromOrdered(uint32_t u) { return std::bit_cast<float>((u & 0x80000000u) ? u & 0x7fffffffu : ~u); }

}  // namespace

rt::Bounds GlMemory::bounds(rt::Buffer visible, const std::array<rt::Buffer, 3>& position,
                            const std::array<float, 3>& constant, size_t rows) const {
    bool anyOnDevice = onDevice(visible);
    for (rt::Buffer b : position) anyOnDevice |= b.valid() && onDevice(b);
    if (rows == 0 || !anyOnDevice) return rt::Memory::bounds(visible, position, constant, rows);
    const_cast<GlMemory*>(this)->flushPending();
    if (!boundsProgram_)
        boundsProgram_ = computeProgram(std::string("#version 450\n") + kParamsBlock + "#define INVOCATION " +
                                            kInvocationIndex + "\n" + kBounds,
                                        "bounds");
    if (!boxBuffer_) glCreateBuffers(1, &boxBuffer_);
    const float inf = std::numeric_limits<float>::infinity();
    std::array<uint32_t, 6> box = {ordered(inf), ordered(inf), ordered(inf), ordered(-inf), ordered(-inf), ordered(-inf)};
    glNamedBufferData(boxBuffer_, sizeof box, box.data(), GL_STREAM_READ);
    afterWrite(Write::Upload, kStorageBlock);
    transferred += sizeof box;
    PassTimer::Scope timed(timer, "bounds", rows);
    unsigned shown = glBuffer(visible);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, shown);
    uint32_t columns = 0;
    for (size_t c = 0; c < 3; ++c) {  // (a component with no column binds `visible`: a block needs a buffer)
        columns |= position[c].valid() ? 1u << c : 0u;
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, static_cast<GLuint>(2 + c),
                         position[c].valid() ? glBuffer(position[c]) : shown);
    }
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, boxBuffer_);
    glUseProgram(boundsProgram_);
    bindParams(paramsBuffer_, {static_cast<uint32_t>(rows), columns, std::bit_cast<uint32_t>(constant[0]),
                               std::bit_cast<uint32_t>(constant[1]), std::bit_cast<uint32_t>(constant[2])});
    dispatchInvocations(rows, 256);
    ++dispatches;
    afterWrite(Write::Dispatch, kCopy);
    glGetNamedBufferSubData(boxBuffer_, 0, sizeof box, box.data());
    transferred += sizeof box;
    ++waits;
    rt::Bounds out;
    for (size_t c = 0; c < 3; ++c) {
        out.low[c] = fromOrdered(box[c]);
        out.high[c] = fromOrdered(box[3 + c]);
    }
    out.empty = !(out.low[0] <= out.high[0]);
    return out;
}

}  // namespace psys::gpu
