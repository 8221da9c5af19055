#include "gpu/compact.h"

#include "gpu/gl_context.h"
#include "gpu/gl_programs.h"
#include "gpu/hazards.h"
#include "codegen_glsl/glsl_shaders.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include <epoxy/gl.h>

namespace psys::gpu {

namespace {

// A group covers 1024 rows, 4 consecutive rows an invocation: a quarter of the
// invocations of one a row, which is what a GL that runs them on the CPU (llvmpipe) pays
// for, and as many loads on a GPU.

// The flags at words[first + i]; per group, its count.
const char* kCount = R"(#version 450
layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer Words { uint w[]; };
layout(std430, binding = 1) buffer Groups { uint groups[]; };
#define first param(0u)
#define n param(1u)
shared uint total;
void main() {
    if (gl_LocalInvocationID.x == 0u) total = 0u;
    barrier();
    uint i = gl_GlobalInvocationID.x * 4u, c = 0u;
    for (uint k = 0u; k < 4u; ++k) c += i + k < n && w[first + i + k] != 0u ? 1u : 0u;
    if (c != 0u) atomicAdd(total, c);
    barrier();
    if (gl_LocalInvocationID.x == 0u) groups[gl_WorkGroupID.x] = total;
}
)";

// Exclusive prefix sums of the groups' counts, in place: invocation t sums a run of
// groups, a scan of the 256 runs in shared memory, then each run is rewritten.
const char* kScan = R"(#version 450
layout(local_size_x = 256) in;
layout(std430, binding = 1) buffer Groups { uint groups[]; };
#define count param(2u)
shared uint runs[256];
void main() {
    uint t = gl_LocalInvocationID.x;
    uint per = (count + 255u) / 256u;
    uint begin = min(t * per, count), end = min(begin + per, count);
    uint sum = 0u;
    for (uint g = begin; g < end; ++g) sum += groups[g];
    runs[t] = sum;
    barrier();
    for (uint step = 1u; step < 256u; step *= 2u) {  // inclusive scan (Hillis and Steele)
        uint add = t >= step ? runs[t - step] : 0u;
        barrier();
        runs[t] += add;
        barrier();
    }
    uint offset = runs[t] - sum;
    for (uint g = begin; g < end; ++g) {
        uint c = groups[g];
        groups[g] = offset;
        offset += c;
    }
    if (t == 255u) groups[count] = runs[255];  // the total, after the offsets
}
)";

// Each group's set rows at its offset, in order, after the total (list[at]: written by the
// first invocation; the rows from list[at + 1]), and the mask zeroed at each where asked
// (Compactor::Clear). A group with none set leaves at once, and one with all set needs
// no scan (the same for every invocation of the group, so no barrier is skipped by some
// and not others): kills are sparse and bunched (objects created together die together),
// and a pool is one launch.
const char* kWrite = R"(#version 450
layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer Words { uint w[]; };
layout(std430, binding = 1) readonly buffer Groups { uint groups[]; };
layout(std430, binding = 2) writeonly buffer List { uint list[]; };
layout(std430, binding = 3) writeonly buffer Mask { uint mask[]; };
layout(std430, binding = 4) readonly buffer Rows { uint rows[]; };
#define first param(0u)
#define n param(1u)
#define at param(3u)
#define clearing param(4u)
#define base param(5u)
#define offset param(6u)
#define mapped param(7u)
shared uint prefix[256];
void clear(uint i) {
    if (clearing != 0u) mask[mapped != 0u ? rows[offset + i] : base + i] = 0u;
}
void main() {
    uint t = gl_LocalInvocationID.x, g = gl_WorkGroupID.x, i = gl_GlobalInvocationID.x * 4u;
    if (gl_GlobalInvocationID.x == 0u) list[at] = groups[gl_NumWorkGroups.x];
    uint count = groups[g + 1u] - groups[g];
    if (count == 0u) return;
    if (count == 4u * gl_WorkGroupSize.x) {
        for (uint k = 0u; k < 4u; ++k) {
            list[at + 1u + groups[g] + 4u * t + k] = i + k;
            clear(i + k);
        }
        return;
    }
    uint flags = 0u, c = 0u;  // this invocation's 4 rows: which are set, how many
    for (uint k = 0u; k < 4u; ++k)
        if (i + k < n && w[first + i + k] != 0u) {
            flags |= 1u << k;
            ++c;
        }
    prefix[t] = c;
    barrier();
    for (uint step = 1u; step < 256u; step *= 2u) {
        uint add = t >= step ? prefix[t - step] : 0u;
        barrier();
        prefix[t] += add;
        barrier();
    }
    uint to = at + 1u + groups[g] + prefix[t] - c;
    for (uint k = 0u; k < 4u; ++k)
        if ((flags & (1u << k)) != 0u) {
            list[to++] = i + k;
            clear(i + k);
        }
}
)";

// The passes' shaders with the parameters' block (gl_context.h) after their version line.
std::string withParams(const char* source) {
    std::string s = source;
    s.insert(s.find('\n') + 1, kParamsBlock);
    return s;
}

void grow(GLuint buffer, size_t& capacity, size_t words) {
    if (words <= capacity) return;
    capacity = std::max(words, 2 * capacity);
    glNamedBufferData(buffer, static_cast<GLsizeiptr>(capacity * 4), nullptr, GL_DYNAMIC_COPY);
    checkAllocation("a compaction", capacity * 4);
}

}  // namespace

Compactor::Compactor() = default;

Compactor::~Compactor() {
    for (GLuint p : {count_, scan_, write_})
        if (p) glDeleteProgram(p);
    if (groups_) glDeleteBuffers(1, &groups_);
    if (params_) glDeleteBuffers(1, &params_);
}

void Compactor::compact(unsigned words, size_t word, size_t n, unsigned out, size_t at, const Clear* clear) {
    if (!count_) {
        count_ = computeProgram(withParams(kCount), "compaction (counts)");
        scan_ = computeProgram(withParams(kScan), "compaction (scan)");
        write_ = computeProgram(withParams(kWrite), "compaction (rows)");
        glCreateBuffers(1, &groups_);
    }
    PassTimer::Scope timed(timer, "compaction", n);
    if (n == 0) {  // nothing set: the total alone
        uint32_t zero = 0;
        glClearNamedBufferSubData(out, GL_R32UI, static_cast<GLintptr>(at * 4), 4, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
        afterWrite(Write::Clear, kCopy);
        return;
    }
    size_t groups = (n + kCompactGroup - 1) / kCompactGroup;
    // The shaders index groups in x alone: a launch splits its dispatches below this.
    if (groups > codegen_glsl::kMaxGroupsX) throw std::logic_error("compaction: more rows than one dispatch takes");
    grow(groups_, groupsCapacity_, groups + 1);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, words);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, groups_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, out);
    // Without a clearing, the mask's and rows' blocks are bound to a buffer the pass never
    // writes through them.
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, clear ? clear->mask : groups_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, clear && clear->rows ? clear->rows : groups_);
    bindParams(params_, {static_cast<uint32_t>(word), static_cast<uint32_t>(n), static_cast<uint32_t>(groups),
                         static_cast<uint32_t>(at), clear ? 1u : 0u, clear ? clear->base : 0u,
                         clear ? clear->offset : 0u, clear && clear->rows ? 1u : 0u});
    glUseProgram(count_);
    glDispatchCompute(static_cast<GLuint>(groups), 1, 1);
    afterWrite(Write::Dispatch, kStorageBlock);  // the counts: the scan reads them
    glUseProgram(scan_);
    glDispatchCompute(1, 1, 1);
    afterWrite(Write::Dispatch, kStorageBlock);  // the offsets: the rows' pass reads them
    glUseProgram(write_);
    glDispatchCompute(static_cast<GLuint>(groups), 1, 1);
    // The list: the host maps it (a read-back region) or reads it (flagged), a shader may
    // read it next; the mask: whatever reads a column (the draws).
    afterWrite(Write::Dispatch, kCopy | kStorageBlock | (clear ? kColumnReaders : 0));
}

}  // namespace psys::gpu

namespace psys::gpu {

std::vector<uint32_t> Compactor::flagged(std::span<const uint32_t> flags) {
    GLuint buffers[2] = {0, 0};
    glCreateBuffers(2, buffers);
    glNamedBufferData(buffers[0], static_cast<GLsizeiptr>(std::max<size_t>(flags.size(), 1) * 4), flags.data(), GL_STATIC_DRAW);
    glNamedBufferData(buffers[1], static_cast<GLsizeiptr>((flags.size() + 1) * 4), nullptr, GL_DYNAMIC_READ);
    compact(buffers[0], 0, flags.size(), buffers[1], 0);
    std::vector<uint32_t> list(flags.size() + 1);
    glGetNamedBufferSubData(buffers[1], 0, static_cast<GLsizeiptr>(list.size() * 4), list.data());
    glDeleteBuffers(2, buffers);
    return std::vector<uint32_t>(list.begin() + 1, list.begin() + 1 + list[0]);
}

}  // namespace psys::gpu
