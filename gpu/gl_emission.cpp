// Rate emissions (and bursts) decided where an emitter's rows are
// (rt::Memory::emitAtRate): a dispatch a site over the rows — rt/emission.h's rules in
// GLSL doubles, each row's accumulator moved on, its objects asked for written into its
// record — then one work group that scans the records in row order: each group's objects
// (the sites into one target) kept while its room lasts (a prefix sum of what was asked,
// clamped), each site's places among its own, the ids of the kept in row order, sites in
// order (prefix sums of the kept); the totals after the records. Counts past 2³² are two
// words (GLSL 4.50 has no 64-bit integers): what a row asks for is at most kMaxCount, a
// sum saturates. More rows than one storage block's records (or columns) hold go as
// windows (rt::Memory::emissionWindow), each scan going on from the totals of the one
// before, on the GPU: nothing waits between them. The differential test
// (tests/gpu/emission_test.cpp) holds this to the host's rule.
#include <epoxy/gl.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "gpu/gl_context.h"
#include "gpu/gl_memory.h"
#include "gpu/gl_programs.h"
#include "gpu/hazards.h"

namespace psys::gpu {

using rt::Buffer;

namespace {

// One site over the rows: params rows, flags (1 rate per row, 2 count per row, 4 kill
// flags, 8 creation times, 16 fresh accumulators, 32 a burst at t1, 64 a burst at each
// row's creation time, 128 each row's end and length of its update; the site from bit
// 8: its record at meta's rt::RecordLayout), the shared rate and count, dt, t1; the rows
// from meta[3] on in the columns (each bound from the window's aligned first row).
// The rule's operations are `precise` and in the host's order: the same doubles.
const char* kEmitRows = R"(
layout(std430, binding = 0) readonly buffer Mask { uint mask[]; };
layout(std430, binding = 1) readonly buffer Killed { uint killed[]; };
layout(std430, binding = 2) readonly buffer Created { uint created[]; };
layout(std430, binding = 3) readonly buffer Rate { uint rates[]; };
layout(std430, binding = 4) readonly buffer Count { uint counts[]; };
layout(std430, binding = 5) buffer Accumulated { uint accumulated[]; };
layout(std430, binding = 6) buffer Runs { uint runs[]; };
layout(std430, binding = 7) readonly buffer Now { uint nows[]; };
layout(std430, binding = 8) readonly buffer Meta { uint meta[]; };
layout(std430, binding = 9) readonly buffer Length { uint lengths[]; };
double ld(uint lo, uint hi) { return packDouble2x32(uvec2(lo, hi)); }
// rt::validCount: NaN, infinite and negative are invalid (0, counted).
double valid(float x, inout uint invalid) {
    if ((floatBitsToUint(x) & 0x7f800000u) == 0x7f800000u || x < 0.0) {
        invalid += 1u;
        return 0.0LF;
    }
    return double(x);
}
// rt::wholeCount.
double whole(double x, inout uint clamped) {
    x = floor(x);
    if (x > 1e18LF) {
        clamped += 1u;
        return 1e18LF;
    }
    return x;
}
void main() {
    uint r = INVOCATION, rows = param(0u), flags = param(1u), site = flags >> 8u;
    if (r >= rows) return;
    uint w = (meta[6u + 4u * site] + r * meta[7u + 4u * site]) * RUN_WORDS, i = meta[3] + r;
    uint invalid = 0u, clamped = 0u, perEvent = 1u;
    uvec2 children = uvec2(0u);
    double firstTime = 0.0LF, spacing = 0.0LF;
    bool clocked = (flags & 128u) != 0u;  // (rt::RateSites::now, length)
    double end = clocked ? ld(nows[2u * i], nows[2u * i + 1u]) : ld(param(6u), param(7u));
    if ((flags & 96u) != 0u) {  // rt::burst: every row of the mask, killed ones too
        if (mask[i] != 0u) {
            double size = valid(uintBitsToFloat((flags & 2u) != 0u ? counts[i] : param(3u)), invalid);
            firstTime = (flags & 64u) != 0u ? ld(created[2u * i], created[2u * i + 1u]) : end;
            if (size >= 1.0LF) {
                double c = whole(size, clamped);
                uint hi = uint(c / 4294967296.0LF);
                precise double lo = c - double(hi) * 4294967296.0LF;
                children = uvec2(uint(lo), hi);
            }
        }
    } else if (mask[i] != 0u && ((flags & 4u) == 0u || killed[i] == 0u)) {
        double t1 = end;
        double dt = clocked ? ld(lengths[2u * i], lengths[2u * i + 1u])
                    : (flags & 8u) != 0u ? t1 - ld(created[2u * i], created[2u * i + 1u]) : ld(param(4u), param(5u));
        double before = (flags & 16u) != 0u ? 0.0LF : ld(accumulated[2u * i], accumulated[2u * i + 1u]);
        double rate = valid(uintBitsToFloat((flags & 1u) != 0u ? rates[i] : param(2u)), invalid);
        double size = valid(uintBitsToFloat((flags & 2u) != 0u ? counts[i] : param(3u)), invalid);
        precise double total = before + rate * dt;
        precise double reached = total + 1e-9LF;
        double events = floor(reached);
        precise double left = total - events;
        uvec2 after = unpackDouble2x32(0.0LF < left ? left : 0.0LF);
        accumulated[2u * i] = after.x;
        accumulated[2u * i + 1u] = after.y;
        if (events >= 1.0LF && size >= 1.0LF) {
            double each = whole(size, clamped);
            perEvent = each >= 4294967295.0LF ? 0xffffffffu : uint(each);
            precise double start = t1 - dt;
            precise double wait = (1.0LF - before) / rate;
            precise double first = start + wait;
            precise double gap = 1.0LF / rate;
            firstTime = first;
            spacing = gap;
            precise double asked = events * each;
            double c = whole(asked, clamped);
            uint hi = uint(c / 4294967296.0LF);
            precise double lo = c - double(hi) * 4294967296.0LF;
            children = uvec2(uint(lo), hi);
        }
    }
    runs[w] = children.x;
    runs[w + 1u] = children.y;
    runs[w + 2u] = invalid | clamped << 16u;  // (the scan sums them, then writes the id here)
    runs[w + 3u] = perEvent;
    uvec2 f = unpackDouble2x32(firstTime), s = unpackDouble2x32(spacing);
    runs[w + 4u] = f.x;
    runs[w + 5u] = f.y;
    runs[w + 6u] = s.x;
    runs[w + 7u] = s.y;
}
)";

// One work group of 256: each invocation a chunk of rows in order. Per site, what its
// rows asked for (a sum of the chunks' sums) before places overwrite it; per group, the
// chunk's sum of what its records asked for (a group's records are one range, rows in
// order, a row's sites in order), an exclusive scan of the sums (by one invocation: 256
// adds), then each record's place and kept; per site, the same over its records' kept
// for their places among the site's; then over the chunks' kept for the ids (rows in
// order, a row's sites in order). `meta`: rows, sites, next id, the first row, then per
// site: its group's room, its group, its first record and stride (rt::RecordLayout), then,
// only where a window goes before, where its totals are in `carry`: what its groups asked
// before these rows (their places start from it, less what it kept: a window's places are
// its own), the ids it took, its totals added to these. The totals from word
// rows · sites · RUN_WORDS of the runs.
const char* kEmitScan = R"(
layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer Meta { uint meta[]; };
layout(std430, binding = 6) buffer Runs { uint runs[]; };
layout(std430, binding = 7) readonly buffer Carry { uint carry[]; };
shared uvec2 partial[256];
shared uint keptBefore[256];
shared uvec2 counted[256];  // invalid, clamped
// a + b, saturating at 2⁶⁴ − 1.
uvec2 add64(uvec2 a, uvec2 b) {
    uint c1, c2, c3;
    uint lo = uaddCarry(a.x, b.x, c1);
    uint hi = uaddCarry(a.y, b.y, c2);
    hi = uaddCarry(hi, c1, c3);
    return (c2 | c3) != 0u ? uvec2(0xffffffffu) : uvec2(lo, hi);
}
uint atMost(uvec2 a, uint room) { return a.y != 0u ? room : min(a.x, room); }
uint room(uint s) { return meta[4u + 4u * s]; }
uint group(uint s) { return meta[5u + 4u * s]; }
uint record(uint s, uint r) { return (meta[6u + 4u * s] + r * meta[7u + 4u * s]) * RUN_WORDS; }
// A total of the windows before (rt::kTotals…; 0 for the first).
uint carried(uint k) { uint c = 4u + 4u * meta[1]; return uint(meta.length()) > c ? carry[meta[c] + k] : 0u; }
uvec2 askedBefore(uint s) { return uvec2(carried(4u + 3u * s), carried(5u + 3u * s)); }
// An exclusive scan of partial[] in place, by invocation 0, which gets the sum back.
uvec2 scanPartial(uint l) {
    uvec2 before = uvec2(0u);
    if (l == 0u)
        for (uint k = 0u; k < 256u; ++k) {
            uvec2 next = add64(before, partial[k]);
            partial[k] = before;
            before = next;
        }
    return before;
}
void main() {
    uint l = gl_LocalInvocationID.x, rows = meta[0], sites = meta[1], totals = rows * sites * RUN_WORDS;
    uint chunk = (rows + 255u) / 256u, begin = min(l * chunk, rows), end = min(begin + chunk, rows);
    uvec2 count = uvec2(0u);
    // What each site asked for, and the invalid and clamped counts (word 2, until the ids).
    for (uint s = 0u; s < sites; ++s) {
        uvec2 sum = uvec2(0u);
        for (uint r = begin; r < end; ++r) {
            uint w = record(s, r);
            sum = add64(sum, uvec2(runs[w], runs[w + 1u]));
            count += uvec2(runs[w + 2u] & 0xffffu, runs[w + 2u] >> 16u);
        }
        partial[l] = sum;
        barrier();
        uvec2 all = scanPartial(l);
        if (l == 0u) {
            uint t = totals + 3u + 3u * s;
            all = add64(all, askedBefore(s));
            runs[t + 1u] = all.x;
            runs[t + 2u] = all.y;
        }
        barrier();
    }
    // Each group's places, while its room lasts.
    for (uint g = 0u; g < sites; ++g) {
        if (group(g) != g) continue;  // (uniform: every invocation skips it)
        uint stride = meta[7u + 4u * g], first = record(g, 0u) + begin * stride * RUN_WORDS;
        uint last = record(g, 0u) + end * stride * RUN_WORDS, space = room(g);
        uvec2 start = uvec2(0u);  // what the group asked in the windows before
        for (uint s = g; s < sites; ++s)
            if (group(s) == g) start = add64(start, askedBefore(s));
        uint from = atMost(start, space);
        uvec2 sum = uvec2(0u);
        for (uint w = first; w < last; w += RUN_WORDS) sum = add64(sum, uvec2(runs[w], runs[w + 1u]));
        partial[l] = sum;
        barrier();
        scanPartial(l);
        barrier();
        uvec2 asked = add64(start, partial[l]);
        for (uint w = first; w < last; w += RUN_WORDS) {
            uint place = atMost(asked, space);
            asked = add64(asked, uvec2(runs[w], runs[w + 1u]));
            runs[w] = place - from;
            runs[w + 1u] = atMost(asked, space) - place;
        }
        barrier();
    }
    // Each site's places among its own objects, and what it kept.
    uint kept = 0u;
    for (uint s = 0u; s < sites; ++s) {
        uint sum = 0u;
        for (uint r = begin; r < end; ++r) sum += runs[record(s, r) + 1u];
        kept += sum;
        keptBefore[l] = sum;
        barrier();
        if (l == 0u) {
            uint before = 0u;
            for (uint k = 0u; k < 256u; ++k) {
                uint next = before + keptBefore[k];
                keptBefore[k] = before;
                before = next;
            }
            runs[totals + 3u + 3u * s] = before + carried(3u + 3u * s);
        }
        barrier();
        uint place = keptBefore[l];
        for (uint r = begin; r < end; ++r) {
            uint w = record(s, r);
            runs[w + SITE_PLACE] = place;
            place += runs[w + 1u];
        }
        barrier();
    }
    keptBefore[l] = kept;
    counted[l] = count;
    barrier();
    if (l == 0u) {
        uvec2 all = uvec2(0u);
        for (uint k = 0u; k < 256u; ++k) all += counted[k];
        runs[totals] = all.x + carried(0u);
        runs[totals + 1u] = all.y + carried(1u);
        uint before = 0u;
        for (uint k = 0u; k < 256u; ++k) {
            uint next = before + keptBefore[k];
            keptBefore[k] = before;
            before = next;
        }
        runs[totals + 2u] = before + carried(2u);
    }
    barrier();
    uint id = meta[2] + carried(2u) + keptBefore[l];
    for (uint r = begin; r < end; ++r)
        for (uint s = 0u; s < sites; ++s) {
            uint w = record(s, r);
            runs[w + 2u] = id;
            id += runs[w + 1u];
        }
}
)";

std::string emissionShader(const char* body, bool rows) {
    std::string header = "#version 450\n#define RUN_WORDS " + std::to_string(rt::kRunWords) + "u\n#define SITE_PLACE " +
                         std::to_string(rt::kRunSitePlace) + "u\n";
    if (rows) header += "layout(local_size_x = 64) in;\n";
    return header + kParamsBlock + "#define INVOCATION " + kInvocationIndex + "\n" + body;
}

uint32_t floatBits(float x) {
    uint32_t u;
    std::memcpy(&u, &x, 4);
    return u;
}
std::pair<uint32_t, uint32_t> doubleWords(double x) {
    uint32_t w[2];
    std::memcpy(w, &x, 8);
    return {w[0], w[1]};
}

}  // namespace

// On the host where the emitters' columns are small and there (a pool whose launches run
// on the host side), wherever the runs buffer was (its length is not the pool's: rows ·
// sites records); on the GPU otherwise.
void GlMemory::emitAtRate(const rt::RateSites& in, Buffer runs) {
    if (in.now.valid() != in.length.valid()) throw std::logic_error("rate sites with a row's end but not its length");
    std::vector<Buffer> used = {in.mask, in.killed, in.created, in.now, in.length};
    for (const rt::RateSites::Site& s : in.sites) used.insert(used.end(), {s.rate, s.count, s.accumulated});
    const size_t sites = in.sites.size(), n = in.rows;
    // Where the emitters' rows are on the host, so are their emissions (a launcher, a
    // cloud: their records and totals read back without a wait); the runs are output only.
    if (n == 0 || std::all_of(used.begin(), used.end(), [&](Buffer b) { return allOnHost({b}); })) {
        overwriteOnHost(runs);
        return rt::Memory::emitAtRate(in, runs);
    }
    if (n > emissionWindow(sites)) throw std::logic_error("an emission operation past one storage block");
    flushPending();
    if (!emitRowsProgram_) emitRowsProgram_ = computeProgram(emissionShader(kEmitRows, true), "rate emissions");
    if (!emitScanProgram_) emitScanProgram_ = computeProgram(emissionShader(kEmitScan, false), "rate emissions' scan");
    PassTimer::Scope timed(timer, "emissions", n * sites);
    unsigned runsGl = overwriteOnDevice(runs);
    // Each column's rows from a multiple of 64 at or before the window's first (an offset
    // every GL takes), so that a window binds no more of a column than a block holds.
    const size_t base = in.first / 64 * 64, end = in.first + n;
    std::vector<uint32_t> meta = {static_cast<uint32_t>(n), static_cast<uint32_t>(sites), in.nextId,
                                  static_cast<uint32_t>(in.first - base)};
    const rt::RecordLayout layout(in);
    for (size_t k = 0; k < sites; ++k)
        meta.insert(meta.end(), {in.sites[in.sites[k].group].room, in.sites[k].group, static_cast<uint32_t>(layout.first[k]),
                                 static_cast<uint32_t>(layout.stride[k])});
    if (in.carry.valid()) meta.push_back(static_cast<uint32_t>(in.carryAt));
    if (!metaBuffer_) glCreateBuffers(1, &metaBuffer_);
    glNamedBufferData(metaBuffer_, static_cast<GLsizeiptr>(meta.size() * 4), meta.data(), GL_STREAM_DRAW);
    afterWrite(Write::Upload, kStorageBlock);
    transferred += meta.size() * 4;
    auto [dt0, dt1] = doubleWords(in.dt);
    auto [t10, t11] = doubleWords(in.t1);
    // A column's rows [base, end) at `binding` (`written`: the dispatch writes them); the
    // runs where it has none (a block must be bound).
    auto bindRows = [&](GLuint binding, Buffer b, bool written = false) {
        if (!b.valid()) return glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, runsGl);
        const auto row = static_cast<GLsizeiptr>(wordsPerRow(elem(b)) * 4);
        glBindBufferRange(GL_SHADER_STORAGE_BUFFER, binding, written ? bound(b) : deviceBuffer(b),
                          static_cast<GLintptr>(base) * row, static_cast<GLsizeiptr>(end - base) * row);
    };
    for (size_t k = 0; k < sites; ++k) {
        const rt::RateSites::Site& s = in.sites[k];
        bindRows(0, in.mask);
        bindRows(1, in.killed);
        bindRows(2, in.created);
        bindRows(3, s.rate);
        bindRows(4, s.count);
        bindRows(5, s.accumulated, true);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 6, runsGl);
        bindRows(7, in.now);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 8, metaBuffer_);
        bindRows(9, in.length);
        using Kind = rt::RateSites::Site::Kind;
        uint32_t flags = (s.rate.valid() ? 1u : 0u) | (s.count.valid() ? 2u : 0u) | (in.killed.valid() ? 4u : 0u) |
                         (in.created.valid() ? 8u : 0u) | (in.fresh ? 16u : 0u) | (s.kind == Kind::Burst ? 32u : 0u) |
                         (s.kind == Kind::AtCreation ? 64u : 0u) | (in.now.valid() ? 128u : 0u) |
                         static_cast<uint32_t>(k) << 8;
        bindParams(paramsBuffer_, {static_cast<uint32_t>(n), flags, floatBits(s.rateValue), floatBits(s.countValue), dt0, dt1,
                                   t10, t11});
        dispatchRows(emitRowsProgram_, n);
    }
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, metaBuffer_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 6, runsGl);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 7, in.carry.valid() ? deviceBuffer(in.carry) : metaBuffer_);
    glUseProgram(emitScanProgram_);
    glDispatchCompute(1, 1, 1);
    ++dispatches;
    afterWrite(Write::Dispatch, kColumnReaders);
}

}  // namespace psys::gpu
