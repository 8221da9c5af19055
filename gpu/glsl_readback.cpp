// What a launch sends back to the host: its counts, the rows it killed (compacted on the
// GPU) and its emission columns, copied on the GPU into a region of one buffer the host
// has mapped (coherent: what the GPU wrote before a fence is there once the fence is
// passed). The host reads the region after a fence: at once (one wait), or — a late
// launch (rt::RowsLaunch::late), which sends back only counts and kills — when the
// run-time collects it (at the next step's start), by which time the GPU has usually finished
// it and the host does not wait at all.
//
// Regions: an immediate read-back uses the words after those late launches hold; late
// launches keep theirs until collected (or settled: read into host memory). When the
// words run out, the late launches are settled and the buffer grows to twice what was
// asked, so that a step's regions soon fit without settling anything early.
#include <algorithm>
#include <cstring>
#include <optional>
#include <string>
#include <stdexcept>

#include <epoxy/gl.h>

#include "gpu/gl_context.h"
#include "gpu/gl_programs.h"
#include "gpu/glsl_program.h"
#include "gpu/hazards.h"

namespace psys::gpu {

using codegen_glsl::LaunchBlock;
using rt::Buffer;
using rt::ColumnLayout;
using rt::Elem;

namespace {

constexpr size_t kKillsAt = 4;  // in a region: counts at words 0–3, the kills' total and rows from word 4

// (%s: the invocation's index, kInvocationIndex, and the parameters' block, kParamsBlock.)
// mask[row of launch row i] = 0 where the kill flag words[flags + i] is set; the row is
// rows[offset + i] where `mapped` (a creation batch's), else base + i.
// Waits for `fence` (flushing what is queued), then deletes it.
void waitFor(GLsync fence) {
    GLenum status = GL_TIMEOUT_EXPIRED;
    while (status == GL_TIMEOUT_EXPIRED) status = glClientWaitSync(fence, GL_SYNC_FLUSH_COMMANDS_BIT, 1'000'000'000);
    glDeleteSync(fence);
    if (status == GL_WAIT_FAILED) throw std::runtime_error("waiting for the GPU failed");
}

}  // namespace

rt::RowsResult GlslBackend::readBack(const rt::RowsLaunch& launch, const Program& p, size_t begin, size_t n,
                                     const std::vector<uint32_t>& block, Late* late) {
    struct Returned {
        Buffer buffer;
        size_t from, at;  // its first word in the launch's words, in the region
    };
    std::vector<Returned> returned;  // the emission columns
    size_t words = kKillsAt;
    bool kills = false;
    for (int c : p.returned) {
        Buffer b = launch.columns[static_cast<size_t>(c)];
        if (!b.valid()) continue;
        if (c == ColumnLayout::kKill) {
            kills = true;
            continue;
        }
        // A rate or count every row shares: the run-time has it (ColumnLayout::sharedEmit).
        if (!launch.clock.perRow() && c >= p.layout.emits && c < p.layout.render &&
            p.layout.emitShared[static_cast<size_t>(c - p.layout.emits)].from != ColumnLayout::Shared::From::Column)
            continue;
        returned.push_back({b, block[LaunchBlock::kColumns + static_cast<size_t>(c)], 0});
    }
    if (!p.counts && !kills && returned.empty()) return {};
    bool listed = late && late->listed;  // the kills into the launch's kill list instead
    if (kills && !listed) words += 1 + n;
    for (Returned& r : returned) {
        r.at = words;
        words += n * GlMemory::wordsPerRow(memory_.elem(r.buffer));
    }
    size_t at = reserveReadback(words);
    std::optional<PassTimer::Scope> timed(std::in_place, &timer_, "read-back", n);
    if (p.counts) glCopyNamedBufferSubData(counts_, readback_, 0, static_cast<GLintptr>(at * 4), 16);
    if (p.counts) afterWrite(Write::Copy, kHostMap);
    timed.reset();
    if (kills) {
        // What is drawn before the run-time takes a late launch's kills (at the next step)
        // must leave them out: the render launches read the alive mask on the GPU, so the
        // compaction clears the killed rows there (the host clears the same rows when it
        // takes the kills, and sends them again: the same 0).
        std::optional<Compactor::Clear> clear;
        if (launch.aliveMask.valid()) {
            bool mapped = !launch.aliveRows.empty() || launch.aliveRowsBuffer.valid();
            unsigned rows = launch.aliveRowsBuffer.valid() ? memory_.deviceBuffer(launch.aliveRowsBuffer)
                            : mapped                        ? memory_.rowList(launch.aliveRows)
                                                            : 0u;
            clear = Compactor::Clear{memory_.deviceBuffer(launch.aliveMask), rows,
                                     static_cast<uint32_t>(begin),
                                     static_cast<uint32_t>(mapped ? begin - launch.aliveRowsFirst : 0)};
        }
        if (listed)
            compactor_.compact(words_, block[LaunchBlock::kColumns + ColumnLayout::kKill], n,
                               memory_.deviceBuffer(launch.killList), 0, clear ? &*clear : nullptr);
        else
            compactor_.compact(words_, block[LaunchBlock::kColumns + ColumnLayout::kKill], n, readback_, at + kKillsAt,
                               clear ? &*clear : nullptr);
        if (listed) memory_.written(launch.killList);
        if (clear) memory_.written(launch.aliveMask);
        memory_.dispatches += 3;  // its passes
    }
    timed.emplace(&timer_, "read-back", n);
    for (const Returned& r : returned)
        glCopyNamedBufferSubData(words_, readback_, static_cast<GLintptr>(r.from * 4),
                                 static_cast<GLintptr>((at + r.at) * 4),
                                 static_cast<GLsizeiptr>(n * GlMemory::wordsPerRow(memory_.elem(r.buffer)) * 4));
    if (!returned.empty()) afterWrite(Write::Copy, kHostMap);
    timed.reset();
    if (late) {  // kept for collect(): no wait now
        readbackUsed_ = at + words;
        late->parts.push_back({begin, at, kills && !listed});
        return {};
    }
    const uint32_t* back = awaitReadback() + at;
    rt::RowsResult result;
    if (p.counts) {
        result = {back[0], back[1], back[2], back[3]};
        memory_.transferred += 16;
    }
    if (kills) {
        Buffer b = launch.columns[ColumnLayout::kKill];
        uint32_t killed = back[kKillsAt];
        memory_.transferred += (1 + killed) * 4;
        auto* flags = static_cast<uint8_t*>(memory_.host(b)) + begin;
        std::memset(flags, 0, n);
        for (uint32_t k = 0; k < killed; ++k) {
            uint32_t row = back[kKillsAt + 1 + k];
            flags[row] = 1;
            killedRows_.push_back(static_cast<uint32_t>(begin) + row);
        }
    }
    for (const Returned& r : returned) {
        Elem e = memory_.elem(r.buffer);
        memory_.transferred += n * GlMemory::wordsPerRow(e) * 4;
        fromWords(back + r.at, e, n, static_cast<char*>(memory_.host(r.buffer)) + begin * rt::elemSize(e));
    }
    return result;
}

size_t GlslBackend::reserveReadback(size_t words) {
    if (readbackUsed_ + words > readbackWords_) {
        // The buffer moves: what late launches keep in it is read first. It is made room
        // for twice what was asked, so that the steps to come fit without moving it again.
        size_t wanted = readbackUsed_ + words;
        for (auto& [ticket, late] : late_) {
            lateEarly_ += !late->settled;
            settle(*late);
        }
        readbackUsed_ = 0;
        ensureReadback(2 * wanted);
    }
    return readbackUsed_;
}

// A buffer of at least `words` words the host has mapped for reading, written by the GPU.
void GlslBackend::ensureReadback(size_t words) {
    if (words <= readbackWords_) return;
    if (readback_) {
        glUnmapNamedBuffer(readback_);
        glDeleteBuffers(1, &readback_);
    }
    readbackWords_ = std::max(words, 2 * readbackWords_);
    auto bytes = static_cast<GLsizeiptr>(readbackWords_ * 4);
    GLbitfield flags = GL_MAP_READ_BIT | GL_MAP_PERSISTENT_BIT | GL_MAP_COHERENT_BIT;
    glCreateBuffers(1, &readback_);
    glNamedBufferStorage(readback_, bytes, nullptr, flags | GL_CLIENT_STORAGE_BIT);
    checkAllocation("reading back", static_cast<size_t>(bytes));
    mappedReadback_ = static_cast<const uint32_t*>(glMapNamedBufferRange(readback_, 0, bytes, flags));
    if (!mappedReadback_) throw std::runtime_error("the GL could not map a buffer for reading back");
}

// The regions were written by copies and the compaction's dispatch, each followed by its
// barrier (gpu/hazards.h); what a host map needs besides is this fence.
const uint32_t* GlslBackend::awaitReadback() {
    waitFor(glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0));
    ++memory_.waits;
    return mappedReadback_;
}

uint64_t GlslBackend::finishLate(std::unique_ptr<Late> late) {
    late->fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    glFlush();  // the GPU starts on it while the host goes on
    uint64_t ticket = nextTicket_++;
    late_[ticket] = std::move(late);
    return ticket;
}

void GlslBackend::settle(Late& late) {
    if (late.settled) return;
    late.settled = true;
    ++lateReads_;
    if (glClientWaitSync(late.fence, 0, 0) == GL_TIMEOUT_EXPIRED) ++lateStalls_;
    waitFor(late.fence);
    late.fence = nullptr;
    for (const Late::Part& part : late.parts) {
        const uint32_t* back = mappedReadback_ + part.at;
        late.counts.killed += back[0];
        late.counts.unstable += back[1];
        late.counts.drawn += back[2];
        late.counts.nonFinite += back[3];
        memory_.transferred += 16;
        if (!part.kills) continue;
        uint32_t killed = back[kKillsAt];
        memory_.transferred += (1 + killed) * 4;
        for (uint32_t k = 0; k < killed; ++k)
            late.rows.push_back(static_cast<uint32_t>(part.begin) + back[kKillsAt + 1 + k]);
    }
}

bool GlslBackend::ready(uint64_t ticket) {
    auto it = late_.find(ticket);
    if (it == late_.end() || it->second->settled) return true;
    if (context_) context_->makeCurrent();
    return glClientWaitSync(it->second->fence, 0, 0) != GL_TIMEOUT_EXPIRED;
}

rt::RowsResult GlslBackend::collect(uint64_t ticket) {
    auto it = late_.find(ticket);
    if (it == late_.end()) throw std::logic_error("collect: no late launch has this ticket");
    if (context_) context_->makeCurrent();
    Late& late = *it->second;
    settle(late);
    killedRows_ = std::move(late.rows);
    rt::RowsResult result = late.counts;
    result.killedRows = killedRows_;
    late_.erase(it);
    // No region is kept once every late launch is settled (read, or waiting to be collected).
    if (std::all_of(late_.begin(), late_.end(), [](const auto& entry) { return entry.second->settled; }))
        readbackUsed_ = 0;
    return result;
}

}  // namespace psys::gpu
