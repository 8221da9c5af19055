// Parents and children whose rows are both on the GPU (rt::Memory's parent operations):
// a child's parent values fetched through its `parents` rows, the survivors whose exports
// an update computes, a kill list's rows cleared in the masks, and the step's end by the rule of rt/ledger.h — a child pool's kill
// list counting its parents' readers down, a parent pool's freeing the unread rows in the
// list's order and freezing the rest, then its frozen rows without readers in row order.
// The ordered pushes are one work group's scan (64 invocations, each a slice of the list
// or the rows, in order), the stack's top moved on by the same dispatch. Each shader is
// the GLSL spelling of what rt/memory.cpp writes for the host.
#include <array>
#include <cstring>

#include <epoxy/gl.h>

#include "codegen_glsl/glsl_shaders.h"
#include "gpu/gl_column.h"
#include "gpu/gl_context.h"
#include "gpu/gl_memory.h"
#include "gpu/gl_programs.h"

namespace psys::gpu {

using rt::Buffer;

namespace {

// A value a row through a list of rows (GlMemory::throughRows): to[first + i] = value(row)
// for row = rows[rowsAt + i], each shader's `value` after this.
const char* kThroughRows = R"(
layout(std430, binding = 0) readonly buffer From { uint from[]; };
layout(std430, binding = 1) buffer To { uint to[]; };
layout(std430, binding = 2) readonly buffer Rows { uint rows[]; };
uint value(uint row);
void main() {
    uint i = INVOCATION, count = param(0u), first = param(1u), rowsAt = param(2u);
    if (i >= count) return;
    to[first + i] = value(rows[rowsAt + i]);
}
)";

// f32 1 or 0: whether the row's parent is alive (from: the alive mask; kSkipRow: none, 0).
const char* kGatherAlive = R"(
uint value(uint row) { return row != 0xFFFFFFFFu && from[row] != 0u ? floatBitsToUint(1.0) : 0u; }
)";

// The rows one level further up (from: the parents' parent rows; kSkipRow stays kSkipRow).
const char* kAncestorRows = R"(
uint value(uint row) { return row == 0xFFFFFFFFu ? row : from[row]; }
)";

// A parent's age at the child's clock, or at its death where it is frozen: rt::ageAt over
// doubles (two words a row, the low first), rounded as C rounds (psys_narrow).
const char* kGatherAge = R"(
layout(std430, binding = 0) readonly buffer Created { uint created[]; };
layout(std430, binding = 1) readonly buffer FrozenAt { uint frozenAt[]; };
layout(std430, binding = 2) readonly buffer Alive { uint alive[]; };
layout(std430, binding = 3) buffer To { uint to[]; };
layout(std430, binding = 4) readonly buffer Rows { uint rows[]; };
layout(std430, binding = 5) readonly buffer Now { uint nowRows[]; };
double word2(uint lo, uint hi) { return packDouble2x32(uvec2(lo, hi)); }
void main() {
    uint i = INVOCATION, count = param(0u), first = param(1u), rowsAt = param(2u), nowAt = param(3u);
    if (i >= count) return;
    uint p = rows[rowsAt + i];
    if (p == 0xFFFFFFFFu) {
        to[first + i] = 0u;
        return;
    }
    uint k = 2u * (nowAt + i);
    double clock = alive[p] == 0u ? word2(frozenAt[2u * p], frozenAt[2u * p + 1u])
                 : param(4u) != 0u ? word2(nowRows[k], nowRows[k + 1u]) : word2(param(5u), param(6u));
    precise double age = clock - word2(created[2u * p], created[2u * p + 1u]);
    to[first + i] = floatBitsToUint(psys_narrow(age));
}
)";

const char* kSurvivors = R"(
layout(std430, binding = 0) readonly buffer Mask { uint mask[]; };
layout(std430, binding = 1) readonly buffer Killed { uint killed[]; };
layout(std430, binding = 2) buffer Out { uint survivors[]; };
void main() {
    uint i = INVOCATION, count = param(0u), first = param(1u);
    if (i >= count) return;
    survivors[first + i] = mask[first + i] != 0u && killed[first + i] == 0u ? 1u : 0u;
}
)";

// A kill list's rows (its count, then launch rows: rt::Memory::releaseRows) and the pool
// row of its i-th; shared by the shaders below (params 1–5; 0, 6, 7 and 8 are theirs).
const char* kKillList = R"(
layout(std430, binding = 0) readonly buffer Killed { uint killed[]; };
layout(std430, binding = 1) readonly buffer Map { uint map[]; };
uint killedRow(uint i) {
    uint r = killed[param(1u) + 1u + i];
    return param(4u) != 0u ? map[param(3u) + r] : param(2u) + r;
}
)";

// The host does not know the list's length: a grid of at most kGrid strides over it.
const char* kReadersGone = R"(
layout(std430, binding = 2) readonly buffer Parents { uint parents[]; };
layout(std430, binding = 3) buffer Readers { uint readers[]; };
void main() {
    uint count = killed[param(1u)], grid = param(5u);
    for (uint i = INVOCATION; i < count; i += grid) {
        uint p = parents[killedRow(i)];
        if (p != 0xFFFFFFFFu) atomicAdd(readers[p], 0xFFFFFFFFu);
    }
}
)";

// The listed rows out of the alive mask, and the updatable one where param 0 says so:
// killed objects that wait for the step's end.
const char* kClearRows = R"(
layout(std430, binding = 2) buffer Updatable { uint updatable[]; };
layout(std430, binding = 3) buffer Alive { uint alive[]; };
void main() {
    uint count = killed[param(1u)], grid = param(5u);
    for (uint i = INVOCATION; i < count; i += grid) {
        uint row = killedRow(i);
        if (param(0u) != 0u) updatable[row] = 0u;
        alive[row] = 0u;
    }
}
)";

// The listed rows' pool rows after those `into` holds; then (kAppended) its count moved on.
const char* kAppend = R"(
layout(std430, binding = 2) buffer Into { uint into[]; };
void main() {
    uint count = killed[param(1u)], grid = param(5u), at = into[0];
    for (uint i = INVOCATION; i < count; i += grid) into[1u + at + i] = killedRow(i);
}
)";
const char* kAppended = R"(
layout(std430, binding = 2) buffer Into { uint into[]; };
void main() {
    if (INVOCATION == 0u) into[0] += killed[param(1u)];
}
)";

// Each listed row's death: `value` (t1 − dt); where param 0 is 1, value − (value −
// created[row]) (a batch's first update: t1 − its age); where it is 2, nows[j] −
// lengths[j] for j = param 8 + the map's first + the launch row (a batch's sub-step), as
// the host rounds it.
const char* kStampDeaths = R"(
layout(std430, binding = 2) buffer FrozenAt { uint frozenAt[]; };
layout(std430, binding = 3) readonly buffer Created { uint created[]; };
layout(std430, binding = 4) readonly buffer Nows { uint nows[]; };
layout(std430, binding = 5) readonly buffer Lengths { uint lengths[]; };
void main() {
    uint count = killed[param(1u)], grid = param(5u);
    double value = packDouble2x32(uvec2(param(6u), param(7u)));
    for (uint i = INVOCATION; i < count; i += grid) {
        uint row = killedRow(i);
        precise double at = value;
        if (param(0u) == 1u) {
            precise double age = value - packDouble2x32(uvec2(created[2u * row], created[2u * row + 1u]));
            at = value - age;
        }
        if (param(0u) == 2u) {
            uint j = param(8u) + param(3u) + killed[param(1u) + 1u + i];
            at = packDouble2x32(uvec2(nows[2u * j], nows[2u * j + 1u])) -
                 packDouble2x32(uvec2(lengths[2u * j], lengths[2u * j + 1u]));
        }
        uvec2 w = unpackDouble2x32(at);
        frozenAt[2u * row] = w.x;
        frozenAt[2u * row + 1u] = w.y;
    }
}
)";

// One work group: each invocation takes a slice of [0, count) in order, counts what it
// pushes, and pushes it at the top plus what the slices before it push.
const char* kScanBlocks = R"(
layout(std430, binding = 2) buffer Stack { uint stack[]; };
layout(std430, binding = 3) buffer Generation { uint generation[]; };
layout(std430, binding = 6) buffer Counters { uint counters[]; };
layout(std430, binding = 7) readonly buffer Readers { uint readers[]; };
layout(std430, binding = 8) buffer Waiting { uint waiting[]; };
shared uint pushes[64];
shared uint frozen[64];
// Of this invocation's pushes and freezes, those of the invocations before it, and all.
uvec4 scan(uint mine, uint mineFrozen) {
    uint lane = gl_LocalInvocationIndex;
    pushes[lane] = mine;
    frozen[lane] = mineFrozen;
    barrier();
    uvec4 sums = uvec4(0u);
    for (uint k = 0u; k < 64u; ++k) {
        if (k < lane) sums.x += pushes[k];
        sums.y += pushes[k];
        sums.z += frozen[k];
    }
    return sums;
}
layout(std430, binding = 9) readonly buffer Parents { uint parents[]; };
layout(std430, binding = 10) buffer ParentReaders { uint parentReaders[]; };
// (`parented`: the pool has parents, each row freed a reader less of its own.)
void push(uint at, uint row, bool parented) {
    stack[at] = row;
    generation[row] += 1u;
    if (parented && parents[row] != 0xFFFFFFFFu) atomicAdd(parentReaders[parents[row]], 0xFFFFFFFFu);
}
)";

// A parent pool's kill list: rows nobody reads pushed in the list's order, the others
// frozen (waiting); none of them alive or updatable any more.
const char* kReleaseUnread = R"(
layout(std430, binding = 4) buffer Updatable { uint updatable[]; };
layout(std430, binding = 5) buffer Alive { uint alive[]; };
void main() {
    uint lane = gl_LocalInvocationIndex, count = killed[param(1u)], top = counters[0];
    uint per = (count + 63u) / 64u, begin = min(lane * per, count), end = min(begin + per, count);
    uint unread = 0u;
    for (uint i = begin; i < end; ++i) unread += readers[killedRow(i)] == 0u ? 1u : 0u;
    uvec4 sums = scan(unread, end - begin - unread);
    uint at = top + sums.x;
    for (uint i = begin; i < end; ++i) {
        uint row = killedRow(i);
        updatable[row] = 0u;
        alive[row] = 0u;
        if (readers[row] == 0u) push(at++, row, param(6u) != 0u); else waiting[row] = 1u;
    }
    barrier();
    if (lane == 0u) {
        counters[0] = top + sums.y;
        counters[1] += sums.z;
    }
}
)";

// The frozen rows among [0, rows) whose readers are all gone, pushed in row order.
const char* kReleaseWaiting = R"(
bool freed(uint row) { return waiting[row] != 0u && readers[row] == 0u; }
void main() {
    uint lane = gl_LocalInvocationIndex, rows = param(0u);
    if (counters[1] == 0u) return;  // (every invocation alike)
    uint top = counters[0];
    uint per = (rows + 63u) / 64u, begin = min(lane * per, rows), end = min(begin + per, rows);
    uint mine = 0u;
    for (uint row = begin; row < end; ++row) mine += freed(row) ? 1u : 0u;
    uvec4 sums = scan(mine, 0u);
    uint at = top + sums.x;
    for (uint row = begin; row < end; ++row) {
        if (!freed(row)) continue;
        waiting[row] = 0u;
        push(at++, row, param(1u) != 0u);
    }
    barrier();
    if (lane == 0u) {
        counters[0] = top + sums.y;
        counters[1] -= sums.y;
    }
}
)";

constexpr uint32_t kGrid = 64 * 1024;

}  // namespace

// The same through a list in a column (a child pool's parents), where the values are.
void GlMemory::gatherThrough(Buffer from, Buffer to, size_t toFirst, Buffer rows, size_t rowsFirst, size_t count) {
    if (count == 0) return;
    Column &f = at(from), &t = at(to);
    if (!f.device && !t.device && !onDevice(rows)) return rt::Memory::gatherThrough(from, to, toFirst, rows, rowsFirst, count);
    for (Column* c : {&f, &t}) {
        flush(*c);
        upload(*c);
    }
    unsigned list = deviceBuffer(rows);
    runRows(gatherProgram(), f.gl, t.gl, wordsPerRow(f.elem), toFirst, list, rowsFirst, count, "gather");
    t.device = true;
}

void GlMemory::gatherAlive(Buffer alive, Buffer to, size_t toFirst, Buffer rows, size_t rowsFirst, size_t count) {
    if (count == 0) return;
    if (!onDevice(rows) && allOnHost({alive, to}))
        return rt::Memory::gatherAlive(alive, to, toFirst, rows, rowsFirst, count);
    throughRows(gatherAliveProgram_, kGatherAlive, "parents alive", alive, to, toFirst, rows, rowsFirst, count);
}

void GlMemory::ancestorRows(Buffer parents, Buffer to, size_t toFirst, Buffer rows, size_t rowsFirst, size_t count) {
    if (count == 0) return;
    if (!onDevice(rows) && allOnHost({parents, to}))
        return rt::Memory::ancestorRows(parents, to, toFirst, rows, rowsFirst, count);
    throughRows(ancestorRowsProgram_, kAncestorRows, "ancestors' rows", parents, to, toFirst, rows, rowsFirst, count);
}

// kThroughRows with `shader`'s value (from, to, rows; count, toFirst, rowsFirst) on the GPU.
void GlMemory::throughRows(unsigned& program, const char* shader, const char* name, Buffer from, Buffer to,
                           size_t toFirst, Buffer rows, size_t rowsFirst, size_t count) {
    flushPending();
    if (!program) program = computeProgram(operationShader(std::string(kThroughRows) + shader), name);
    PassTimer::Scope timed(timer, "gather", count);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, deviceBuffer(from));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, bound(to));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, deviceBuffer(rows));
    bindParams(paramsBuffer_, {static_cast<uint32_t>(count), static_cast<uint32_t>(toFirst),
                               static_cast<uint32_t>(rowsFirst)});
    dispatchRows(program, count);
}

void GlMemory::gatherAge(Buffer created, Buffer frozenAt, Buffer alive, Buffer to, size_t toFirst, Buffer rows,
                         size_t rowsFirst, size_t count, double now, Buffer nowRows, size_t nowFirst) {
    if (count == 0) return;
    if (!onDevice(rows) && allOnHost({created, frozenAt, alive, to, nowRows}))
        return rt::Memory::gatherAge(created, frozenAt, alive, to, toFirst, rows, rowsFirst, count, now, nowRows, nowFirst);
    flushPending();
    if (!gatherAgeProgram_)
        gatherAgeProgram_ = computeProgram(operationShader(codegen_glsl::narrowHelper() + kGatherAge), "parents' ages");
    PassTimer::Scope timed(timer, "gather", count);
    std::array<uint32_t, 2> w{};
    std::memcpy(w.data(), &now, 8);
    unsigned list = deviceBuffer(rows);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, deviceBuffer(created));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, deviceBuffer(frozenAt));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, deviceBuffer(alive));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, bound(to));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, list);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, nowRows.valid() ? deviceBuffer(nowRows) : list);
    bindParams(paramsBuffer_, {static_cast<uint32_t>(count), static_cast<uint32_t>(toFirst),
                               static_cast<uint32_t>(rowsFirst), static_cast<uint32_t>(nowFirst),
                               nowRows.valid() ? 1u : 0u, w[0], w[1]});
    dispatchRows(gatherAgeProgram_, count);
}

void GlMemory::stampDeaths(Buffer killed, size_t killedAt, uint32_t base, Buffer map, size_t mapFirst, Buffer frozenAt,
                           double t1, double dt, Buffer created, Buffer nows, Buffer lengths, size_t clocksFirst) {
    if (allOnHost({killed, map, frozenAt, created, nows, lengths}))
        return rt::Memory::stampDeaths(killed, killedAt, base, map, mapFirst, frozenAt, t1, dt, created, nows, lengths,
                                       clocksFirst);
    flushPending();
    uint32_t grid = killListGrid(killed, killedAt);
    if (grid == 0) return;
    killListProgram(stampDeathsProgram_, kStampDeaths, "deaths' times");
    PassTimer::Scope timed(timer, "release", grid);
    double value = created.valid() ? t1 : t1 - dt;  // (the host's rounding of t1 − dt)
    std::array<uint32_t, 2> w{};
    std::memcpy(w.data(), &value, 8);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, bound(frozenAt));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, created.valid() ? deviceBuffer(created) : deviceBuffer(frozenAt));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, nows.valid() ? deviceBuffer(nows) : deviceBuffer(frozenAt));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, nows.valid() ? deviceBuffer(lengths) : deviceBuffer(frozenAt));
    bindKillList(killed, killedAt, base, map, mapFirst, grid, nows.valid() ? 2u : created.valid() ? 1u : 0u, w,
                 static_cast<uint32_t>(clocksFirst));
    dispatchRows(stampDeathsProgram_, grid);
}

void GlMemory::survivors(Buffer mask, Buffer killed, Buffer out, size_t first, size_t count) {
    if (count == 0) return;
    if (allOnHost({mask, killed, out})) return rt::Memory::survivors(mask, killed, out, first, count);
    flushPending();
    if (!survivorsProgram_) survivorsProgram_ = computeProgram(operationShader(kSurvivors), "survivors");
    PassTimer::Scope timed(timer, "survivors", count);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, deviceBuffer(mask));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, deviceBuffer(killed));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, bound(out));
    bindParams(paramsBuffer_, {static_cast<uint32_t>(count), static_cast<uint32_t>(first)});
    dispatchRows(survivorsProgram_, count);
}

// The invocations over a kill list in `killed` from word `killedAt`, whose length the host
// does not know: one a row it may hold, at most kGrid (0: it holds none).
uint32_t GlMemory::killListGrid(Buffer killed, size_t killedAt) const {
    size_t most = rows(killed) > killedAt ? rows(killed) - killedAt - 1 : 0;
    return static_cast<uint32_t>(std::min<size_t>(most, kGrid));
}

// A program over a kill list (kKillList's helpers, then `body`), made on first use.
void GlMemory::killListProgram(unsigned& program, const char* body, const char* name) {
    if (!program) program = computeProgram(operationShader(std::string(kKillList) + body), name);
}

// The kill list's bindings and parameters (kKillList's).
void GlMemory::bindKillList(Buffer killed, size_t killedAt, uint32_t base, Buffer map, size_t mapFirst, uint32_t grid,
                            uint32_t mode, std::array<uint32_t, 2> value, uint32_t extra) {
    unsigned list = deviceBuffer(killed);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, list);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, map.valid() ? deviceBuffer(map) : list);
    bindParams(paramsBuffer_, {mode, static_cast<uint32_t>(killedAt), base, static_cast<uint32_t>(mapFirst),
                               map.valid() ? 1u : 0u, grid, value[0], value[1], extra});
}

void GlMemory::clearRows(const rt::PoolRows& pool, Buffer killed, size_t killedAt, uint32_t base, Buffer map,
                         size_t mapFirst) {
    if (allOnHost({pool.updatable, pool.alive, killed, map}))
        return rt::Memory::clearRows(pool, killed, killedAt, base, map, mapFirst);
    flushPending();
    uint32_t grid = killListGrid(killed, killedAt);
    if (grid == 0) return;
    killListProgram(clearRowsProgram_, kClearRows, "clear of the killed");
    PassTimer::Scope timed(timer, "clear", grid);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, pool.updatable.valid() ? bound(pool.updatable) : deviceBuffer(pool.alive));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, bound(pool.alive));
    bindKillList(killed, killedAt, base, map, mapFirst, grid, pool.updatable.valid() ? 1u : 0u);
    dispatchRows(clearRowsProgram_, grid);
}

void GlMemory::appendKills(Buffer killed, size_t killedAt, uint32_t base, Buffer map, size_t mapFirst, Buffer into) {
    if (allOnHost({killed, map, into})) return rt::Memory::appendKills(killed, killedAt, base, map, mapFirst, into);
    flushPending();
    uint32_t grid = killListGrid(killed, killedAt);
    if (grid == 0) return;
    killListProgram(appendProgram_, kAppend, "kills gathered");
    killListProgram(appendedProgram_, kAppended, "kills gathered: count");
    PassTimer::Scope timed(timer, "release", grid);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, bound(into));
    bindKillList(killed, killedAt, base, map, mapFirst, grid);
    dispatchRows(appendProgram_, grid);
    dispatchRows(appendedProgram_, 1);  // the same bindings and parameters
}

void GlMemory::readersGone(Buffer killed, size_t killedAt, uint32_t base, Buffer map, size_t mapFirst, Buffer parents,
                           Buffer readers) {
    if (allOnHost({killed, map, parents, readers}))
        return rt::Memory::readersGone(killed, killedAt, base, map, mapFirst, parents, readers);
    flushPending();
    uint32_t grid = killListGrid(killed, killedAt);
    if (grid == 0) return;
    killListProgram(readersGoneProgram_, kReadersGone, "readers gone");
    PassTimer::Scope timed(timer, "release", grid);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, deviceBuffer(parents));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, bound(readers));
    bindKillList(killed, killedAt, base, map, mapFirst, grid);
    dispatchRows(readersGoneProgram_, grid);
}

void GlMemory::releaseUnread(const rt::PoolRows& pool, Buffer killed, size_t killedAt, uint32_t base, Buffer map,
                             size_t mapFirst) {
    if (allOnHost({pool.stack, pool.generation, pool.updatable, pool.alive, pool.counters, pool.readers, pool.waiting,
                   pool.parents, pool.parentReaders, killed, map}))
        return rt::Memory::releaseUnread(pool, killed, killedAt, base, map, mapFirst);
    flushPending();
    if (rows(killed) <= killedAt + 1) return;
    if (!releaseUnreadProgram_)
        releaseUnreadProgram_ = computeProgram(operationShader(std::string(kKillList) + kScanBlocks + kReleaseUnread),
                                               "release of the unread");
    PassTimer::Scope timed(timer, "release", 64);
    bindScanBlocks(pool);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, bound(pool.updatable));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, bound(pool.alive));
    bindKillList(killed, killedAt, base, map, mapFirst, 64, 0, {pool.parents.valid() ? 1u : 0u, 0});
    dispatchRows(releaseUnreadProgram_, 64);
}

void GlMemory::releaseWaiting(const rt::PoolRows& pool, size_t rows) {
    if (rows == 0) return;
    if (allOnHost({pool.stack, pool.generation, pool.counters, pool.readers, pool.waiting, pool.parents,
                   pool.parentReaders}))
        return rt::Memory::releaseWaiting(pool, rows);
    flushPending();
    if (!releaseWaitingProgram_)
        releaseWaitingProgram_ =
            computeProgram(operationShader(std::string(kScanBlocks) + kReleaseWaiting), "release of the waiting");
    PassTimer::Scope timed(timer, "release", 64);
    bindScanBlocks(pool);
    bindParams(paramsBuffer_, {static_cast<uint32_t>(rows), pool.parents.valid() ? 1u : 0u});
    dispatchRows(releaseWaitingProgram_, 64);
}

void GlMemory::bindScanBlocks(const rt::PoolRows& pool) {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, bound(pool.stack));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, bound(pool.generation));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 6, bound(pool.counters));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 7, deviceBuffer(pool.readers));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 8, bound(pool.waiting));
    // (Where it has none, the pool's own readers stand in: the shaders read neither.)
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 9, deviceBuffer(pool.parents.valid() ? pool.parents : pool.readers));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 10,
                     pool.parents.valid() ? bound(pool.parentReaders) : deviceBuffer(pool.readers));
}

}  // namespace psys::gpu
