// What a launch sends back to the host: its counts, the rows it killed (compacted on the
// GPU) and its emission columns, copied on the GPU into a region of one buffer. The host
// reads a region with glGetNamedBufferSubData: at once (one wait), or — a late launch
// (rt::RowsLaunch::late), which sends back only counts and kills — when the run-time
// collects it (at the next step's start), by which time the GPU has usually finished it
// (its fence says so) and the read does not wait.
//
// Not through a mapping: a persistent, coherent mapping is right once a fence after the
// copies has passed (ARB_buffer_storage), and on Mesa 22.3's zink such a fence passed
// before the copy of a draw's counts had run (the fluid sample at frame 32, the step its
// pool's columns grow: 132 drops drawn, 0 read; the test "what a draw counts is read
// back after the copy that carries it"). A read the GL itself makes is ordered after
// every earlier command on any driver; the fence only says when it will not wait.
//
// Regions: an immediate read-back uses the words after those late launches hold; late
// launches keep theirs until collected (or fetched: read into host memory). When the
// words run out, the late launches are fetched and the buffer grows to twice what was
// asked, so that a step's regions soon fit without settling anything early.
#include <algorithm>
#include <cstring>
#include <optional>
#include <span>
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
            if (launch.emissionsStay)  // (the memory's emission reads them: a row killed emits nothing)
                memory_.adopt(b, begin, n, words_, block[LaunchBlock::kColumns + static_cast<size_t>(c)]);
            continue;
        }
        // A rate or count every row shares: the run-time has it (ColumnLayout::sharedEmit).
        if (!launch.clock.perRow() && c >= p.layout.emits && c < p.layout.render &&
            p.layout.emitShared[static_cast<size_t>(c - p.layout.emits)].from != ColumnLayout::Shared::From::Column)
            continue;
        if (launch.emissionsStay) {  // (the memory decides the emissions where the rows are)
            memory_.adopt(b, begin, n, words_, block[LaunchBlock::kColumns + static_cast<size_t>(c)]);
            continue;
        }
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
    if (p.counts) afterWrite(Write::Copy, kCopy);
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
    if (!returned.empty()) afterWrite(Write::Copy, kCopy);
    timed.reset();
    if (late) {  // kept for collect(): no wait now
        readbackUsed_ = at + words;
        late->parts.push_back({begin, at, kills && !listed});
        return {};
    }
    // One wait: the first read waits for the GPU, the others find their words written.
    ++memory_.waits;
    uint32_t head[kKillsAt + 1] = {};
    std::span<const uint32_t> first = readRegion(at, kills ? kKillsAt + 1 : kKillsAt);
    std::copy(first.begin(), first.end(), head);
    rt::RowsResult result;
    if (p.counts) {
        result = {head[0], head[1], head[2], head[3]};
        memory_.transferred += 16;
    }
    if (kills) {
        Buffer b = launch.columns[ColumnLayout::kKill];
        uint32_t killed = head[kKillsAt];
        memory_.transferred += (1 + killed) * 4;
        auto* flags = static_cast<uint8_t*>(memory_.host(b)) + begin;
        std::memset(flags, 0, n);
        for (uint32_t row : readRegion(at + kKillsAt + 1, killed)) {
            flags[row] = 1;
            killedRows_.push_back(static_cast<uint32_t>(begin) + row);
        }
    }
    for (const Returned& r : returned) {
        Elem e = memory_.elem(r.buffer);
        size_t w = n * GlMemory::wordsPerRow(e);
        memory_.transferred += w * 4;
        fromWords(readRegion(at + r.at, w).data(), e, n, static_cast<char*>(memory_.host(r.buffer)) + begin * rt::elemSize(e));
    }
    return result;
}

size_t GlslBackend::reserveReadback(size_t words) {
    if (readbackUsed_ + words > readbackWords_) {
        // The buffer moves: what late launches keep in it is read first. It is made room
        // for twice what was asked, so that the steps to come fit without moving it again.
        size_t wanted = readbackUsed_ + words;
        for (auto& [ticket, late] : late_) {
            lateEarly_ += !late->fetched;
            fetch(*late);
        }
        readbackUsed_ = 0;
        ensureReadback(2 * wanted);
    }
    return readbackUsed_;
}

// A buffer of at least `words` words, written by the GPU, read by the host (readRegion).
void GlslBackend::ensureReadback(size_t words) {
    if (words <= readbackWords_) return;
    if (readback_) glDeleteBuffers(1, &readback_);
    readbackWords_ = std::max(words, 2 * readbackWords_);
    auto bytes = static_cast<GLsizeiptr>(readbackWords_ * 4);
    glCreateBuffers(1, &readback_);
    glNamedBufferStorage(readback_, bytes, nullptr, GL_CLIENT_STORAGE_BIT);
    checkAllocation("reading back", static_cast<size_t>(bytes));
}

// The regions were written by copies and the compaction's dispatch, each followed by its
// barrier (gpu/hazards.h: a dispatch's for a copy, which a read by the GL is); the GL
// orders the read after them, waiting for them where they have not run.
std::span<const uint32_t> GlslBackend::readRegion(size_t at, size_t words) {
    readCopy_.resize(words);
    if (words)
        glGetNamedBufferSubData(readback_, static_cast<GLintptr>(at * 4), static_cast<GLsizeiptr>(words * 4),
                                readCopy_.data());
    return readCopy_;
}

uint64_t GlslBackend::finishLate(std::unique_ptr<Late> late) {
    late->fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    glFlush();  // the GPU starts on it while the host goes on
    uint64_t ticket = nextTicket_++;
    late_[ticket] = std::move(late);
    return ticket;
}

void GlslBackend::fetch(Late& late) {
    if (late.fetched) return;
    late.fetched = true;
    ++lateReads_;
    if (glClientWaitSync(late.fence, 0, 0) == GL_TIMEOUT_EXPIRED) ++lateStalls_;
    waitFor(late.fence);
    late.fence = nullptr;
    for (const Late::Part& part : late.parts) {
        // The counts and the kills' total, then the rows killed (a region has room for
        // every row of its dispatch).
        uint32_t head[kKillsAt + 1] = {};
        std::span<const uint32_t> first = readRegion(part.at, part.kills ? kKillsAt + 1 : kKillsAt);
        std::copy(first.begin(), first.end(), head);
        late.counts.killed += head[0];
        late.counts.unstable += head[1];
        late.counts.drawn += head[2];
        late.counts.nonFinite += head[3];
        memory_.transferred += 16;
        if (!part.kills) continue;
        uint32_t killed = head[kKillsAt];
        memory_.transferred += (1 + killed) * 4;
        for (uint32_t row : readRegion(part.at + kKillsAt + 1, killed))
            late.rows.push_back(static_cast<uint32_t>(part.begin) + row);
    }
}

bool GlslBackend::ready(uint64_t ticket) {
    auto it = late_.find(ticket);
    if (it == late_.end() || it->second->fetched) return true;
    if (context_) context_->makeCurrent();
    return glClientWaitSync(it->second->fence, 0, 0) != GL_TIMEOUT_EXPIRED;
}

rt::RowsResult GlslBackend::collect(uint64_t ticket) {
    auto it = late_.find(ticket);
    if (it == late_.end()) throw std::logic_error("collect: no late launch has this ticket");
    if (context_) context_->makeCurrent();
    Late& late = *it->second;
    fetch(late);
    killedRows_ = std::move(late.rows);
    rt::RowsResult result = late.counts;
    result.killedRows = killedRows_;
    late_.erase(it);
    // No region is kept once every late launch is fetched (read, or waiting to be collected).
    if (std::all_of(late_.begin(), late_.end(), [](const auto& entry) { return entry.second->fetched; }))
        readbackUsed_ = 0;
    return result;
}

}  // namespace psys::gpu
