// A pool's rows kept on the GPU (rt::Memory::allocateRows): the allocation rule of
// rt/allocation.h, the release of a late launch's kills, the rows a step created made
// updatable, a batch's ids and creation times from its runs and its first update's
// sub-step clocks — each one dispatch over
// buffers that stay on the GPU, so that the host keeps only counts (the stack's top, the
// high-water mark, the live count) and a step's bookkeeping does not grow with its objects.
// Each shader is the GLSL spelling of the rule rt/memory.cpp writes for the host; the
// differential tests hold the two to the same rows, ids and generations.
#include <algorithm>
#include <array>
#include <cstring>
#include <initializer_list>
#include <string>

#include <epoxy/gl.h>

#include "codegen_glsl/glsl_shaders.h"
#include "gpu/gl_context.h"
#include "gpu/gl_memory.h"
#include "gpu/gl_programs.h"
#include "gpu/hazards.h"

namespace psys::gpu {

using rt::Buffer;

std::string operationShader(const std::string& body) {
    return std::string("#version 450\nlayout(local_size_x = 64) in;\n") + kParamsBlock + "#define INVOCATION " +
           kInvocationIndex + "\n#define RUN_WORDS " + std::to_string(rt::kRunWords) + "u\n" + body;
}

namespace {

// FreeRows::row(k): stack[top − 1 − k] while the stack lasts, then past the high-water mark.
const char* kAllocate = R"(
layout(std430, binding = 0) readonly buffer Stack { uint stack[]; };
layout(std430, binding = 2) buffer Out { uint rows[]; };
layout(std430, binding = 3) buffer Updatable { uint updatable[]; };
layout(std430, binding = 4) buffer Alive { uint alive[]; };
layout(std430, binding = 6) buffer Counters { uint counters[]; };
void main() {
    uint k = INVOCATION, n = param(0u), top = param(1u), highWater = param(2u), at = param(3u);
    if (k >= n) return;
    if (k == 0u) counters[0] = top - min(n, top);
    uint row = k < top ? stack[top - 1u - k] : highWater + (k - top);
    rows[at + k] = row;
    updatable[row] = 0u;
    alive[row] = 1u;
}
)";

// The kills' count, then their launch rows; each pushed at top + i. A grid of at most
// kReleaseGrid invocations strides over them: the host does not know how many there are.
const char* kRelease = R"(
layout(std430, binding = 0) readonly buffer Killed { uint killed[]; };
layout(std430, binding = 1) readonly buffer Map { uint map[]; };
layout(std430, binding = 2) buffer Stack { uint stack[]; };
layout(std430, binding = 3) buffer Generation { uint generation[]; };
layout(std430, binding = 4) buffer Updatable { uint updatable[]; };
layout(std430, binding = 5) buffer Alive { uint alive[]; };
layout(std430, binding = 6) readonly buffer Counters { uint counters[]; };
void main() {
    uint at = param(1u), base = param(2u), mapFirst = param(3u), mapped = param(4u), grid = param(5u);
    uint top = counters[0], count = killed[at];
    for (uint i = INVOCATION; i < count; i += grid) {
        uint r = killed[at + 1u + i];
        uint row = mapped != 0u ? map[mapFirst + r] : base + r;
        stack[top + i] = row;
        generation[row] += 1u;
        updatable[row] = 0u;
        alive[row] = 0u;
    }
}
)";

// After a release: the stack's top moved on by its count.
const char* kPushed = R"(
layout(std430, binding = 0) readonly buffer Killed { uint killed[]; };
layout(std430, binding = 6) buffer Counters { uint counters[]; };
void main() {
    if (INVOCATION == 0u) counters[0] += killed[param(1u)];
}
)";

const char* kFresh = R"(
layout(std430, binding = 0) readonly buffer Rows { uint rows[]; };
layout(std430, binding = 3) buffer Updatable { uint updatable[]; };
layout(std430, binding = 4) readonly buffer Alive { uint alive[]; };
void main() {
    uint i = INVOCATION, first = param(0u), count = param(1u);
    if (i >= count) return;
    uint row = rows[first + i];
    updatable[row] = alive[row];
}
)";

// Rows of a mask cleared through a map: mask[map[mapFirst + rows[i]]] = 0.
const char* kClearMapped = R"(
layout(std430, binding = 0) readonly buffer Rows { uint rows[]; };
layout(std430, binding = 1) readonly buffer Map { uint map[]; };
layout(std430, binding = 4) buffer Mask { uint mask[]; };
void main() {
    uint i = INVOCATION, count = param(0u), mapFirst = param(1u);
    if (i >= count) return;
    mask[map[mapFirst + rows[i]]] = 0u;
}
)";

// What the identify and parents shaders share: the runs (records of rt::kRunWords words,
// in rt::ObjectRuns' form) from word `base` on, `count` of them; the run of object r —
// the last whose first object is at or before r (a run of no objects shares its first
// with the next, which wins).
const char* kRunOf = R"(
layout(std430, binding = 0) readonly buffer Runs { uint runs[]; };
uint runOf(uint r, uint base, uint count) {
    uint lo = 0u, hi = count - 1u;
    while (lo < hi) {
        uint mid = (lo + hi + 1u) >> 1u;
        if (runs[base + mid * RUN_WORDS] <= r) lo = mid; else hi = mid - 1u;
    }
    return base + lo * RUN_WORDS;
}
)";

// Object k of the run at word u written at row `at`, its time rounded as rt::eventTime's:
// `precise`, no fused multiply-add.
const char* kRunObjects = R"(
layout(std430, binding = 1) buffer Created { uint created[]; };
layout(std430, binding = 2) buffer Ids { uint ids[]; };
void identifyObject(uint u, uint k, uint at) {
    double firstTime = packDouble2x32(uvec2(runs[u + 4u], runs[u + 5u]));
    double spacing = packDouble2x32(uvec2(runs[u + 6u], runs[u + 7u]));
    precise double offset = double(k / runs[u + 3u]) * spacing;
    precise double t = firstTime + offset;
    uvec2 words = unpackDouble2x32(t);
    created[at * 2u] = words.x;
    created[at * 2u + 1u] = words.y;
    ids[at] = runs[u + 2u] + k;
}
)";

// A batch's objects from runs the host sends: each object's mask, and the objects of the
// runs (an object past its run's count is one of a site's records: identifyRecords).
const char* kIdentify = R"(
layout(std430, binding = 3) buffer Mask { uint mask[]; };
void main() {
    uint r = INVOCATION, n = param(0u), kept = param(1u), runCount = param(2u), first = param(3u);
    if (r >= n) return;
    mask[first + r] = r < kept ? 1u : 0u;
    if (runCount == 0u) return;
    uint u = runOf(r, 0u, runCount), k = r - runs[u];
    if (k < runs[u + 1u]) identifyObject(u, k, first + r);
}
)";

// The same from a site's records where emitAtRate left them: object r of the records
// from record `base` on, its times and id at `first` + r.
const char* kIdentifyRecords = R"(
void main() {
    uint r = INVOCATION, n = param(0u), records = param(1u), first = param(2u), base = param(3u) * RUN_WORDS;
    if (r >= n) return;
    uint u = runOf(r, base, records);
    identifyObject(u, r - runs[u], first + r);
}
)";

// Object r of the records from record `base` on: its parent the row of its record's
// emitter (`stride` records a row; through the emitter batch's rows where `mapped`), and
// a reader more of it where it was kept.
const char* kParentsFromRecords = R"(
layout(std430, binding = 1) readonly buffer Map { uint map[]; };
layout(std430, binding = 2) buffer Parents { uint parents[]; };
layout(std430, binding = 3) buffer Readers { uint readers[]; };
void main() {
    uint r = INVOCATION, n = param(0u), records = param(1u), first = param(2u), base = param(3u) * RUN_WORDS;
    uint stride = param(4u), mapped = param(5u), mapFirst = param(6u), kept = param(7u);
    if (r >= n) return;
    uint j = (runOf(r, base, records) - base) / RUN_WORDS / stride;
    uint row = mapped != 0u ? map[mapFirst + j] : mapFirst + j;
    parents[first + r] = row;
    if (r < kept) atomicAdd(readers[row], 1u);
}
)";

// Sub-step k of a batch's first update: rt/clock.h's subStepCount and subStepEnd over
// doubles, `precise` (no fused multiply-add), rounded to float as C rounds.
const char* kSubStepClocks = R"(
layout(std430, binding = 0) readonly buffer Created { uint created[]; };
layout(std430, binding = 1) readonly buffer Mask { uint mask[]; };
layout(std430, binding = 2) buffer Step { uint step[]; };
layout(std430, binding = 3) buffer Now { uint now[]; };
layout(std430, binding = 4) buffer Dt { uint dt[]; };
layout(std430, binding = 5) buffer Length { uint lengths[]; };  // (param 8: whether given)
double word2(uint lo, uint hi) { return packDouble2x32(uvec2(lo, hi)); }
void main() {
    uint i = INVOCATION, n = param(0u), first = param(1u), k = param(2u), most = param(3u);
    if (i >= n) return;
    uint at = first + i;
    if ((k == 1u ? mask[at] : step[at]) == 0u) {
        step[at] = 0u;
        return;
    }
    double t1 = word2(param(4u), param(5u)), limit = word2(param(6u), param(7u));
    precise double span = t1 - word2(created[2u * at], created[2u * at + 1u]);
    uint steps = 1u;
    if (limit > 0.0LF && span > limit) {
        precise double q = span / limit;
        steps = uint(min(ceil(q), double(most)));
    }
    step[at] = k <= steps ? 1u : 0u;
    if (k > steps) return;
    precise double fraction = double(k) / double(steps);
    precise double t = (t1 - span) + span * fraction;
    uvec2 w = unpackDouble2x32(k == steps ? t1 : t);
    now[2u * at] = w.x;
    now[2u * at + 1u] = w.y;
    precise double length = span / double(steps);
    dt[at] = floatBitsToUint(psys_narrow(length));
    if (param(8u) == 0u) return;
    uvec2 l = unpackDouble2x32(length);
    lengths[2u * at] = l.x;
    lengths[2u * at + 1u] = l.y;
}
)";

constexpr uint32_t kReleaseGrid = 64 * 1024;

}  // namespace

// Where every buffer an operation touches is small and on the host (a pool of a few rows
// whose launches run on the host side: hostRows), it runs there, as rt::Memory writes it,
// and the columns stay on the host.
bool GlMemory::allOnHost(std::initializer_list<Buffer> buffers) const {
    if (hostRows == 0) return false;
    return std::all_of(buffers.begin(), buffers.end(), [&](Buffer b) {
        return !b.valid() || (!onDevice(b) && rows(b) <= hostRows);
    });
}

// The bound program over `invocations` invocations; what it wrote read by any reader of a column.
void GlMemory::dispatchRows(unsigned program, size_t invocations) {
    glUseProgram(program);
    dispatchInvocations(invocations, 64);
    ++dispatches;
    afterWrite(Write::Dispatch, kColumnReaders);
}

unsigned GlMemory::bound(Buffer b) {
    unsigned gl = deviceBuffer(b);
    written(b);
    return gl;
}

void GlMemory::allocateRows(const rt::PoolRows& pool, size_t top, size_t highWater, size_t n, Buffer out,
                            size_t outFirst) {
    if (n == 0) return;
    if (allOnHost({pool.stack, pool.generation, pool.updatable, pool.alive, pool.counters, out}))
        return rt::Memory::allocateRows(pool, top, highWater, n, out, outFirst);
    flushPending();
    if (!allocateProgram_) allocateProgram_ = computeProgram(operationShader(kAllocate), "allocation");
    PassTimer::Scope timed(timer, "allocation", n);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, deviceBuffer(pool.stack));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, bound(out));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, bound(pool.updatable));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, bound(pool.alive));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 6, bound(pool.counters));
    bindParams(paramsBuffer_, {static_cast<uint32_t>(n), static_cast<uint32_t>(top), static_cast<uint32_t>(highWater),
                               static_cast<uint32_t>(outFirst)});
    dispatchRows(allocateProgram_, n);
}

void GlMemory::releaseRows(const rt::PoolRows& pool, Buffer killed, size_t killedAt, uint32_t base, Buffer map,
                           size_t mapFirst) {
    if (allOnHost({pool.stack, pool.generation, pool.updatable, pool.alive, pool.counters, killed, map}))
        return rt::Memory::releaseRows(pool, killed, killedAt, base, map, mapFirst);
    flushPending();
    size_t most = rows(killed) > killedAt ? rows(killed) - killedAt - 1 : 0;
    if (most == 0) return;
    if (!releaseProgram_) releaseProgram_ = computeProgram(operationShader(kRelease), "release");
    if (!pushedProgram_) pushedProgram_ = computeProgram(operationShader(kPushed), "release count");
    auto grid = static_cast<uint32_t>(std::min<size_t>(most, kReleaseGrid));
    PassTimer::Scope timed(timer, "release", grid);
    unsigned list = deviceBuffer(killed);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, list);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, map.valid() ? deviceBuffer(map) : list);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, bound(pool.stack));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, bound(pool.generation));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, bound(pool.updatable));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, bound(pool.alive));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 6, bound(pool.counters));
    bindParams(paramsBuffer_, {0u, static_cast<uint32_t>(killedAt), base, static_cast<uint32_t>(mapFirst),
                               map.valid() ? 1u : 0u, grid});
    dispatchRows(releaseProgram_, grid);
    dispatchRows(pushedProgram_, 1);  // the same bindings and parameters
}

void GlMemory::markFresh(const rt::PoolRows& pool, Buffer rows, size_t first, size_t count) {
    if (count == 0) return;
    if (allOnHost({rows, pool.updatable, pool.alive})) return rt::Memory::markFresh(pool, rows, first, count);
    flushPending();
    if (!freshProgram_) freshProgram_ = computeProgram(operationShader(kFresh), "fresh rows");
    PassTimer::Scope timed(timer, "fresh", count);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, deviceBuffer(rows));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, bound(pool.updatable));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, deviceBuffer(pool.alive));
    bindParams(paramsBuffer_, {static_cast<uint32_t>(first), static_cast<uint32_t>(count)});
    dispatchRows(freshProgram_, count);
}

void GlMemory::clearMapped(Buffer mask, std::span<const uint32_t> rows, Buffer map, size_t mapFirst) {
    if (rows.empty()) return;
    if (allOnHost({mask, map})) {
        auto* m = static_cast<uint8_t*>(host(mask));
        const auto* through = static_cast<const uint32_t*>(view(map)) + mapFirst;
        for (uint32_t r : rows) m[through[r]] = 0;
        return;
    }
    flushPending();
    if (!clearMappedProgram_) clearMappedProgram_ = computeProgram(operationShader(kClearMapped), "clear through a map");
    PassTimer::Scope timed(timer, "clear", rows.size());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, rowList(rows));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, deviceBuffer(map));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, bound(mask));
    bindParams(paramsBuffer_, {static_cast<uint32_t>(rows.size()), static_cast<uint32_t>(mapFirst)});
    dispatchRows(clearMappedProgram_, rows.size());
}

void GlMemory::subStepClocks(Buffer created, Buffer mask, Buffer step, Buffer now, Buffer dt, Buffer length,
                             size_t first, size_t n, uint32_t k, uint32_t most, double t1, double limit) {
    if (n == 0) return;
    if (allOnHost({created, mask, step, now, dt, length}))
        return rt::Memory::subStepClocks(created, mask, step, now, dt, length, first, n, k, most, t1, limit);
    flushPending();
    if (!subStepProgram_)
        subStepProgram_ = computeProgram(operationShader(codegen_glsl::narrowHelper() + kSubStepClocks), "sub-step clocks");
    PassTimer::Scope timed(timer, "sub-steps", n);
    std::array<uint32_t, 2> end{}, h{};
    std::memcpy(end.data(), &t1, 8);
    std::memcpy(h.data(), &limit, 8);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, deviceBuffer(created));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, deviceBuffer(mask));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, bound(step));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, bound(now));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, bound(dt));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, length.valid() ? bound(length) : bound(dt));  // (a block must be bound)
    bindParams(paramsBuffer_, {static_cast<uint32_t>(n), static_cast<uint32_t>(first), k, most, end[0], end[1], h[0], h[1],
                               length.valid() ? 1u : 0u});
    dispatchRows(subStepProgram_, n);
}

void GlMemory::identify(const rt::ObjectRuns& runs, size_t n, size_t kept, Buffer created, Buffer ids, Buffer mask,
                        size_t first) {
    if (n == 0) return;
    if (allOnHost({created, ids, mask})) return rt::Memory::identify(runs, n, kept, created, ids, mask, first);
    flushPending();
    if (!identifyProgram_) identifyProgram_ = computeProgram(operationShader(std::string(kRunOf) + kRunObjects + kIdentify), "identify");
    std::vector<uint32_t> words(std::max<size_t>(runs.size(), 1) * rt::kRunWords);  // (a block is never empty)
    for (size_t u = 0; u < runs.size(); ++u) {
        uint32_t* w = words.data() + u * rt::kRunWords;
        w[0] = runs.first[u];
        w[1] = runs.count[u];
        w[2] = runs.id[u];
        w[3] = runs.perEvent[u];
        std::memcpy(w + 4, &runs.firstTime[u], 8);
        std::memcpy(w + 6, &runs.spacing[u], 8);
    }
    PassTimer::Scope timed(timer, "identify", n);
    if (!runsBuffer_) glCreateBuffers(1, &runsBuffer_);
    glNamedBufferData(runsBuffer_, static_cast<GLsizeiptr>(words.size() * 4), words.data(), GL_STREAM_DRAW);
    afterWrite(Write::Upload, kStorageBlock);
    transferred += words.size() * 4;
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, runsBuffer_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, bound(created));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, bound(ids));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, bound(mask));
    bindParams(paramsBuffer_, {static_cast<uint32_t>(n), static_cast<uint32_t>(kept),
                               static_cast<uint32_t>(runs.size()), static_cast<uint32_t>(first)});
    dispatchRows(identifyProgram_, n);
}

void GlMemory::identifyRecords(Buffer runs, size_t firstRecord, size_t records, size_t objects, Buffer created,
                               Buffer ids, size_t first) {
    if (objects == 0) return;
    if (!onDevice(runs) && allOnHost({created, ids}))  // (the runs' length is not a pool's)
        return rt::Memory::identifyRecords(runs, firstRecord, records, objects, created, ids, first);
    flushPending();
    if (!identifyRecordsProgram_) identifyRecordsProgram_ = computeProgram(operationShader(std::string(kRunOf) + kRunObjects + kIdentifyRecords), "identify from records");
    PassTimer::Scope timed(timer, "identify", objects);
    // (Records the host side's emitters wrote: only the group's go up.)
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, deviceRows(runs, firstRecord * rt::kRunWords, records * rt::kRunWords));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, bound(created));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, bound(ids));
    bindParams(paramsBuffer_, {static_cast<uint32_t>(objects), static_cast<uint32_t>(records),
                               static_cast<uint32_t>(first), static_cast<uint32_t>(firstRecord)});
    dispatchRows(identifyRecordsProgram_, objects);
}

void GlMemory::parentsFromRecords(Buffer runs, size_t firstRecord, size_t records, size_t stride, Buffer map,
                                  size_t mapFirst, size_t objects, size_t kept, Buffer parents, size_t first,
                                  Buffer readers) {
    if (objects == 0) return;
    if (!onDevice(runs) && allOnHost({map, parents, readers}))
        return rt::Memory::parentsFromRecords(runs, firstRecord, records, stride, map, mapFirst, objects, kept, parents,
                                              first, readers);
    flushPending();
    if (!parentsProgram_)
        parentsProgram_ = computeProgram(operationShader(std::string(kRunOf) + kParentsFromRecords), "parents from records");
    PassTimer::Scope timed(timer, "parents", objects);
    unsigned list = deviceRows(runs, firstRecord * rt::kRunWords, records * rt::kRunWords);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, list);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, map.valid() ? deviceBuffer(map) : list);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, bound(parents));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, bound(readers));
    bindParams(paramsBuffer_, {static_cast<uint32_t>(objects), static_cast<uint32_t>(records),
                               static_cast<uint32_t>(first), static_cast<uint32_t>(firstRecord),
                               static_cast<uint32_t>(stride), map.valid() ? 1u : 0u, static_cast<uint32_t>(mapFirst),
                               static_cast<uint32_t>(kept)});
    dispatchRows(parentsProgram_, objects);
}

}  // namespace psys::gpu
