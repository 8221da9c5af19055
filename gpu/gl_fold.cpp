// The neighbour folds on the GPU (rt::Backend::fold; docs/gpu.md, "Neighbours"): the
// grid is built where the positions are and the folds are written where the update reads
// them — nothing comes back to the host.
//
// Each side's columns are packed into one buffer by copies (the mask, the position, the
// exports the terms read: codegen_glsl/glsl_fold.h). Then: every row of the other side
// counted into its bucket (atomics); the counts scanned into each bucket's first place
// (prefix sums, as the compactor's); the rows scattered to their places (atomics: in no
// set order) and each bucket's rows sorted by row — so the grid is the host's, the same
// every run; the other side's columns copied in that order (a bucket's read in a row);
// then one invocation per object (in the grid's order where a type folds over itself)
// walks the 27 cells around it (codegen_glsl::foldShader), and the results are adopted as the fold columns.
#include <epoxy/gl.h>

#include <bit>
#include <map>
#include <string>

#include "codegen_glsl/glsl_fold.h"
#include "core/hash.h"
#include "gpu/gl_context.h"
#include "gpu/gl_programs.h"
#include "gpu/fold_work.h"
#include "gpu/glsl_backend.h"
#include "gpu/hazards.h"

namespace psys::gpu {

namespace {

// Bucket counts to each bucket's first place: per group of 1024 buckets its sum (pass 0),
// the groups' sums scanned in place by one group (pass 1), each group's buckets scanned
// from its offset (pass 2), the total after the last bucket.
const char* kGridScan = R"(
layout(local_size_x = 256) in;
layout(std430, binding = 4) readonly buffer Counts { uint counts[]; };
layout(std430, binding = 5) buffer Start { uint start[]; };
layout(std430, binding = 6) buffer Groups { uint groups[]; };
shared uint runs[256];
void scan(uint t) {  // runs[t] becomes the sum of runs[0..t] (Hillis and Steele)
    for (uint step = 1u; step < 256u; step *= 2u) {
        uint add = t >= step ? runs[t - step] : 0u;
        barrier();
        runs[t] += add;
        barrier();
    }
}
void main() {
    uint n = param(0u), pass = param(1u), t = gl_LocalInvocationID.x, g = gl_WorkGroupID.x;
    if (pass == 1u) {
        uint count = (n + 1023u) / 1024u, per = (count + 255u) / 256u;
        uint begin = min(t * per, count), end = min(begin + per, count), sum = 0u;
        for (uint k = begin; k < end; ++k) sum += groups[k];
        runs[t] = sum;
        barrier();
        scan(t);
        uint offset = runs[t] - sum;
        for (uint k = begin; k < end; ++k) {
            uint c = groups[k];
            groups[k] = offset;
            offset += c;
        }
        if (t == 255u) start[n] = runs[255];
        return;
    }
    uint base = g * 1024u + t * 4u, c[4], sum = 0u;
    for (uint k = 0u; k < 4u; ++k) {
        c[k] = base + k < n ? counts[base + k] : 0u;
        sum += c[k];
    }
    runs[t] = sum;
    barrier();
    scan(t);
    if (pass == 0u) {
        if (t == 255u) groups[g] = runs[255];
        return;
    }
    uint offset = groups[g] + runs[t] - sum;
    for (uint k = 0u; k < 4u; ++k) {
        if (base + k < n) start[base + k] = offset;
        offset += c[k];
    }
}
)";

// Each row to a place in its bucket (the order within one set by the sort after).
const char* kGridScatter = R"(
layout(local_size_x = 256) in;
layout(std430, binding = 3) readonly buffer BucketOf { uint bucketOf[]; };
layout(std430, binding = 4) buffer Cursor { uint cursor[]; };
layout(std430, binding = 5) writeonly buffer Sorted { uint sorted[]; };
void main() {
    uint r = INVOCATION;
    if (r >= param(0u)) return;
    uint b = bucketOf[r];
    if (b != 0xffffffffu) sorted[atomicAdd(cursor[b], 1u)] = r;
}
)";

// Each bucket's rows in row order (insertion sort: a bucket holds a few).
const char* kSort = R"(
layout(local_size_x = 256) in;
layout(std430, binding = 4) readonly buffer Start { uint start[]; };
layout(std430, binding = 5) buffer Sorted { uint sorted[]; };
void main() {
    uint b = INVOCATION;
    if (b >= param(0u)) return;
    uint first = start[b], end = start[b + 1u];
    for (uint j = first + 1u; j < end; ++j) {
        uint v = sorted[j], k = j;
        while (k > first && sorted[k - 1u] > v) {
            sorted[k] = sorted[k - 1u];
            --k;
        }
        sorted[k] = v;
    }
}
)";

// The other side's slots in the grid's order: a bucket's rows read in a row by the fold.
const char* kPlace = R"(
layout(local_size_x = 256) in;
layout(std430, binding = 2) readonly buffer Other { uint ow[]; };
layout(std430, binding = 4) readonly buffer Start { uint start[]; };
layout(std430, binding = 5) readonly buffer Sorted { uint sorted[]; };
layout(std430, binding = 6) writeonly buffer Placed { uint placed[]; };
void main() {
    uint j = INVOCATION, rows = param(0u), slots = param(1u);
    if (j >= start[param(2u)]) return;  // (the total, after the last bucket)
    uint r = sorted[j];
    for (uint s = 0u; s < slots; ++s) placed[s * rows + j] = ow[s * rows + r];
}
)";

// A utility shader's text: its parameters (kParamsBlock) and its invocation's index.
std::string utility(const char* body) {
    return std::string("#version 450\n") + kParamsBlock + "#define INVOCATION " + kInvocationIndex + "\n" + body;
}

// A buffer of at least `words` words (grown, never shrunk; its contents not kept).
void ensure(unsigned& buffer, size_t& capacity, size_t words) {
    words = std::max<size_t>(words, 1);
    if (buffer && capacity >= words) return;
    if (buffer) glDeleteBuffers(1, &buffer);
    glCreateBuffers(1, &buffer);
    capacity = std::max(words, 2 * capacity);
    glNamedBufferData(buffer, static_cast<GLsizeiptr>(capacity * 4), nullptr, GL_DYNAMIC_COPY);
    checkAllocation("a neighbour grid", capacity * 4);
}

// Each side's mask, position and the exports its terms read, packed into one buffer.
void pack(FoldWork& w, GlMemory& memory, const rt::FoldLaunch& l, const codegen_glsl::FoldShader& shader) {
    std::map<uint32_t, unsigned> sent;  // (a mask the host keeps goes up once, for both sides where they are one type)
    auto packSide = [&](const rt::FoldLaunch::Side& side, int position, const std::vector<std::pair<int, int>>& slots,
                        int which) {
        std::vector<rt::Buffer> columns = {side.mask};
        for (int c = 0; c < 3; ++c) columns.push_back(side.exports.at(static_cast<size_t>(position))[static_cast<size_t>(c)]);
        for (auto [e, c] : slots) columns.push_back(side.exports.at(static_cast<size_t>(e))[static_cast<size_t>(c)]);
        ensure(w.buffers[which], w.capacity[which], columns.size() * side.rows);
        if (side.rows == 0) return;
        for (size_t s = 0; s < columns.size(); ++s) {
            auto found = sent.find(columns[s].id);
            unsigned gl = found != sent.end() ? found->second : sent[columns[s].id] = memory.deviceBuffer(columns[s]);
            glCopyNamedBufferSubData(gl, w.buffers[which], 0, static_cast<GLintptr>(s * side.rows * 4),
                                     static_cast<GLsizeiptr>(side.rows * 4));
        }
        memory.staged += columns.size() * side.rows * 4;
    };
    packSide(l.self, l.group->selfPosition, shader.self, FoldWork::kSelf);
    packSide(l.other, l.group->otherPosition, shader.other, FoldWork::kOther);
    afterWrite(Write::Copy, kStorageBlock);
}

void bind(const FoldWork& w, GLuint binding, int buffer) {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, w.buffers[buffer]);
}

void dispatch(FoldWork& w, GlMemory& memory, unsigned program, size_t invocations,
              std::initializer_list<uint32_t> params) {
    glUseProgram(program);
    bindParams(w.params, params);
    dispatchInvocations(invocations, 256);
    ++memory.dispatches;
    afterWrite(Write::Dispatch, kStorageBlock | kCopy);
}

// The grid of the other side's rows: counted into buckets, scanned, scattered, each
// bucket sorted, the other side's slots placed in its order.
void buildGrid(FoldWork& w, GlMemory& memory, uint32_t rows, uint32_t buckets, uint32_t inverse,
               uint32_t slots) {
    using W = FoldWork;
    ensure(w.buffers[W::kBucketOf], w.capacity[W::kBucketOf], rows);
    ensure(w.buffers[W::kCounts], w.capacity[W::kCounts], buckets);
    ensure(w.buffers[W::kStart], w.capacity[W::kStart], buckets + 1);
    ensure(w.buffers[W::kGroups], w.capacity[W::kGroups], buckets / 1024 + 1);
    ensure(w.buffers[W::kCursor], w.capacity[W::kCursor], buckets);
    ensure(w.buffers[W::kSorted], w.capacity[W::kSorted], rows);
    ensure(w.buffers[W::kPlaced], w.capacity[W::kPlaced], static_cast<size_t>(slots) * rows);
    uint32_t zero = 0;
    glClearNamedBufferSubData(w.buffers[W::kCounts], GL_R32UI, 0, buckets * 4, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    afterWrite(Write::Clear, kStorageBlock);
    bind(w, 2, W::kOther);
    bind(w, 3, W::kBucketOf);
    bind(w, 4, W::kCounts);
    dispatch(w, memory, w.count, rows, {rows, buckets - 1, inverse});
    bind(w, 5, W::kStart);
    bind(w, 6, W::kGroups);
    glUseProgram(w.scan);
    for (uint32_t pass : {0u, 1u, 2u}) {
        bindParams(w.params, {buckets, pass});
        glDispatchCompute(pass == 1 ? 1 : (buckets + 1023) / 1024, 1, 1);
        ++memory.dispatches;
        afterWrite(Write::Dispatch, kStorageBlock | kCopy);
    }
    glCopyNamedBufferSubData(w.buffers[W::kStart], w.buffers[W::kCursor], 0, 0, buckets * 4);
    afterWrite(Write::Copy, kStorageBlock);
    bind(w, 4, W::kCursor);
    bind(w, 5, W::kSorted);
    dispatch(w, memory, w.scatter, rows, {rows});
    bind(w, 4, W::kStart);
    dispatch(w, memory, w.sort, buckets, {buckets});
    bind(w, 6, W::kPlaced);
    dispatch(w, memory, w.place, rows, {rows, slots, buckets});
}

}  // namespace

void GlslBackend::forgetFold(const ir::Kernel& pair) {
    if (!fold_) return;
    if (auto it = fold_->folds.find(&pair); it != fold_->folds.end()) {
        glDeleteProgram(it->second.first);
        fold_->folds.erase(it);
    }
}

bool GlslBackend::fold(const rt::FoldLaunch& l) {
    // Where nothing of it is on the GPU (small pools the host side runs), the host folds.
    bool anyOnDevice = memory_.onDevice(l.self.mask) || memory_.onDevice(l.other.mask);
    for (const auto* side : {&l.self, &l.other})
        for (const auto& e : side->exports)
            for (rt::Buffer b : e) anyOnDevice |= b.valid() && memory_.onDevice(b);
    if (!anyOnDevice) return false;
    memory_.flushPending();
    if (!fold_) {
        fold_ = std::make_unique<FoldWork>();
        fold_->count = computeProgram(codegen_glsl::gridCountShader(), "the neighbour grid's count");
        fold_->scan = computeProgram(utility(kGridScan), "the neighbour grid's scan");
        fold_->scatter = computeProgram(utility(kGridScatter), "the neighbour grid's scatter");
        fold_->sort = computeProgram(utility(kSort), "the neighbour grid's sort");
        fold_->place = computeProgram(utility(kPlace), "the neighbour grid's placing");
    }
    FoldWork& w = *fold_;
    auto found = w.folds.find(l.pair);
    if (found == w.folds.end()) {
        codegen_glsl::FoldShader shader = codegen_glsl::foldShader(*l.object, *l.pair);
        unsigned program = compile(shader.source, "the folds of " + l.object->name);
        found = w.folds.emplace(l.pair, std::pair{program, std::move(shader)}).first;
    }
    auto& [program, shader] = found->second;
    const ir::NeighbourGroup& group = *l.group;
    PassTimer::Scope timed(&timer_, "fold", l.self.rows);
    pack(w, memory_, l, shader);
    auto rows = static_cast<uint32_t>(l.other.rows);
    uint32_t buckets = core::gridBuckets(l.other.rows);
    uint32_t inverse = std::bit_cast<uint32_t>(1.0f / (group.radius * core::kCellMargin));
    buildGrid(w, memory_, rows, buckets, inverse, static_cast<uint32_t>(4 + shader.other.size()));

    // The folds: the launch's words, then one invocation per object and one for the row of
    // empty folds.
    size_t selfRows = l.self.rows;
    std::vector<uint32_t> words(codegen_glsl::kFoldExterns, 0);
    words[0] = static_cast<uint32_t>(selfRows);
    words[1] = rows;
    words[2] = buckets - 1;
    words[3] = inverse;
    words[4] = std::bit_cast<uint32_t>(group.radius * group.radius);
    words[5] = l.same ? 1 : 0;
    // (the externs: the module's every one; the shader reads those its terms name)
    for (size_t e = 0; e < l.externCount; ++e)
        for (int c = 0; c < 4; ++c) words.push_back(std::bit_cast<uint32_t>(l.externs[e].f[static_cast<size_t>(c)]));
    ensure(w.buffers[FoldWork::kWords], w.capacity[FoldWork::kWords], words.size());
    sendThrough(w.upload, w.buffers[FoldWork::kWords], 0, words.size() * 4, words.data());
    memory_.transferred += words.size() * 4;
    afterWrite(Write::Upload, kStorageBlock);
    ensure(w.buffers[FoldWork::kResults], w.capacity[FoldWork::kResults],
           static_cast<size_t>(shader.width) * (selfRows + 1));
    bind(w, 0, FoldWork::kWords);
    bind(w, 2, FoldWork::kSelf);
    bind(w, 3, FoldWork::kPlaced);
    bind(w, 4, FoldWork::kStart);
    bind(w, 5, FoldWork::kSorted);
    bind(w, 6, FoldWork::kResults);
    glUseProgram(program);
    dispatchInvocations(selfRows + 1, 64);
    ++memory_.dispatches;
    afterWrite(Write::Dispatch, kCopy);
    // Into the fold columns, where the update's gathers read them.
    int at = 0;
    for (size_t k = 0; k < l.object->folds.size(); ++k) {
        const ir::Fold& f = l.object->folds[k];
        if (f.group != l.pair->site) continue;
        for (int c = 0; c < f.type.width; ++c, ++at)
            memory_.adopt(l.results[k][static_cast<size_t>(c)], 0, selfRows + 1, w.buffers[FoldWork::kResults],
                          static_cast<size_t>(at) * (selfRows + 1));
    }
    return true;
}

}  // namespace psys::gpu
