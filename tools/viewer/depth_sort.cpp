#include "depth_sort.h"

#include <glm/gtc/type_ptr.hpp>

#include "render.h"

namespace psys::viewer {

namespace {

// Each row's key: its depth along the eye's view (more negative: farther), a large number
// for rows not drawn (after every drawn one), +inf for the padding past the last row.
const char* kKeys = R"(#version 450 core
layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer Visible { float visible[]; };
layout(std430, binding = 1) readonly buffer X { float px[]; };
layout(std430, binding = 2) readonly buffer Y { float py[]; };
layout(std430, binding = 3) readonly buffer Z { float pz[]; };
layout(std430, binding = 4) writeonly buffer Keys { float keys[]; };
layout(std430, binding = 5) writeonly buffer Rows { uint rows[]; };
uniform uint count;
uniform uint padded;
uniform ivec3 fromColumn;  // per component: 1 where it has a column
uniform vec3 constant;
uniform vec4 depthRow;     // the view matrix's third row: eye z = dot(depthRow, (p, 1))
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= padded) return;
    rows[i] = i;
    if (i >= count) {
        keys[i] = uintBitsToFloat(0x7f800000u);
        return;
    }
    vec3 p = vec3(fromColumn.x == 1 ? px[i] : constant.x, fromColumn.y == 1 ? py[i] : constant.y,
                  fromColumn.z == 1 ? pz[i] : constant.z);
    keys[i] = visible[i] == 0.0 ? 3.0e38 : dot(depthRow, vec4(p, 1.0));
}
)";

// One step of a bitonic sort over `padded` (a power of two) pairs, ascending.
const char* kSort = R"(#version 450 core
layout(local_size_x = 256) in;
layout(std430, binding = 4) buffer Keys { float keys[]; };
layout(std430, binding = 5) buffer Rows { uint rows[]; };
uniform uint padded;
uniform uint k;
uniform uint j;
void main() {
    uint i = gl_GlobalInvocationID.x;
    uint l = i ^ j;
    if (i >= padded || l <= i) return;
    bool ascending = (i & k) == 0u;
    float a = keys[i], b = keys[l];
    if ((a > b) == ascending && a != b) {
        keys[i] = b;
        keys[l] = a;
        uint r = rows[i];
        rows[i] = rows[l];
        rows[l] = r;
    }
}
)";

const char* kGather = R"(#version 450 core
layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer Source { float source[]; };
layout(std430, binding = 5) readonly buffer Rows { uint rows[]; };
layout(std430, binding = 6) writeonly buffer Target { float target[]; };
uniform uint count;
uniform uint sorted;    // 1: row i is rows[i]
uniform uint stride;
uniform uint offset;
uniform uint constantOnly;  // 1: no source, `constant` for every row
uniform float constant;
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    target[i * stride + offset] = constantOnly == 1u ? constant : source[sorted == 1u ? rows[i] : i];
}
)";

GLuint groups(size_t n) { return static_cast<GLuint>((n + 255) / 256); }

}  // namespace

DepthSort::DepthSort() {
    keys_ = linkComputeProgram(kKeys);
    sort_ = linkComputeProgram(kSort);
    gather_ = linkComputeProgram(kGather);
    glCreateBuffers(1, &keyBuffer_);
    glCreateBuffers(1, &indexBuffer_);
}

DepthSort::~DepthSort() {
    glDeleteBuffers(1, &keyBuffer_);
    glDeleteBuffers(1, &indexBuffer_);
    glDeleteProgram(keys_);
    glDeleteProgram(sort_);
    glDeleteProgram(gather_);
}

void DepthSort::reserve(size_t padded) {
    if (padded <= capacity_) return;
    glNamedBufferData(keyBuffer_, static_cast<GLsizeiptr>(padded * sizeof(float)), nullptr, GL_DYNAMIC_DRAW);
    glNamedBufferData(indexBuffer_, static_cast<GLsizeiptr>(padded * sizeof(uint32_t)), nullptr, GL_DYNAMIC_DRAW);
    capacity_ = padded;
}

void DepthSort::order(GLuint visible, const std::array<GLuint, 3>& position, const glm::vec3& constant, size_t rows,
                      const glm::mat4& view) {
    size_t padded = 1;
    while (padded < rows) padded <<= 1;
    reserve(padded);
    glUseProgram(keys_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, visible);
    for (int c = 0; c < 3; ++c)  // (an unused binding still needs a buffer: the visible column)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, static_cast<GLuint>(1 + c), position[static_cast<size_t>(c)] ? position[static_cast<size_t>(c)] : visible);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, keyBuffer_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, indexBuffer_);
    glUniform1ui(glGetUniformLocation(keys_, "count"), static_cast<GLuint>(rows));
    glUniform1ui(glGetUniformLocation(keys_, "padded"), static_cast<GLuint>(padded));
    glUniform3i(glGetUniformLocation(keys_, "fromColumn"), position[0] != 0, position[1] != 0, position[2] != 0);
    glUniform3f(glGetUniformLocation(keys_, "constant"), constant.x, constant.y, constant.z);
    glm::vec4 depthRow{view[0][2], view[1][2], view[2][2], view[3][2]};  // (column-major)
    glUniform4fv(glGetUniformLocation(keys_, "depthRow"), 1, glm::value_ptr(depthRow));
    glDispatchCompute(groups(padded), 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    glUseProgram(sort_);
    glUniform1ui(glGetUniformLocation(sort_, "padded"), static_cast<GLuint>(padded));
    for (size_t k = 2; k <= padded; k <<= 1)
        for (size_t j = k >> 1; j > 0; j >>= 1) {
            glUniform1ui(glGetUniformLocation(sort_, "k"), static_cast<GLuint>(k));
            glUniform1ui(glGetUniformLocation(sort_, "j"), static_cast<GLuint>(j));
            glDispatchCompute(groups(padded), 1, 1);
            glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        }
}

void DepthSort::gather(GLuint source, GLuint target, size_t rows, bool sorted, size_t stride, size_t offset,
                       float constant) {
    reserve(1);  // (an unused binding still needs a buffer)
    glUseProgram(gather_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, source ? source : target);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, indexBuffer_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 6, target);
    glUniform1ui(glGetUniformLocation(gather_, "count"), static_cast<GLuint>(rows));
    glUniform1ui(glGetUniformLocation(gather_, "sorted"), sorted ? 1u : 0u);
    glUniform1ui(glGetUniformLocation(gather_, "stride"), static_cast<GLuint>(stride));
    glUniform1ui(glGetUniformLocation(gather_, "offset"), static_cast<GLuint>(offset));
    glUniform1ui(glGetUniformLocation(gather_, "constantOnly"), source ? 0u : 1u);
    glUniform1f(glGetUniformLocation(gather_, "constant"), constant);
    glDispatchCompute(groups(rows), 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_VERTEX_ATTRIB_ARRAY_BARRIER_BIT);
}

}  // namespace psys::viewer
