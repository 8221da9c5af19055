// The GLSL backend's memory: every column has a host copy and a GL buffer, and one of
// them is the column's true value.
//
// A column starts on the host. It moves to the GPU when a kernel writes it there (an
// object's state and exports: GlslBackend adopts them) or when a copy or scatter between
// columns runs on the GPU; from then on steps leave it there. It comes back to the host
// only when the host asks for its address (`host`, `view`), so the run-time's bookkeeping
// reads what it needs and an object's state stays on the GPU from step to step. `read`
// and `write` of a column on the GPU move only the rows they name.
//
// On the GPU a column is 32-bit words: one per row (f32, u32, u8 widened) or two (f64).
#pragma once

#include <cstdint>

#include <initializer_list>
#include <memory>
#include <vector>

#include "gpu/pass_timer.h"
#include "rt/memory.h"

namespace psys::gpu {

class GlMemory final : public rt::Memory {
public:
    GlMemory();
    ~GlMemory() override;
    rt::Buffer create(rt::Elem elem, size_t rows) override;
    void resize(rt::Buffer buffer, size_t rows) override;
    void release(rt::Buffer buffer) override;
    size_t rows(rt::Buffer buffer) const override;
    rt::Elem elem(rt::Buffer buffer) const override;
    void read(rt::Buffer buffer, size_t first, size_t count, void* out) const override;
    void write(rt::Buffer buffer, size_t first, size_t count, const void* in) override;
    void copy(rt::Buffer from, size_t fromFirst, rt::Buffer to, size_t toFirst, size_t count) override;
    void scatter(rt::Buffer from, size_t fromFirst, rt::Buffer to, std::span<const uint32_t> rows) override;
    void gather(rt::Buffer from, rt::Buffer to, size_t toFirst, std::span<const uint32_t> rows) override;
    void clear(rt::Buffer buffer, size_t first, size_t count) override;
    void fill(rt::Buffer buffer, size_t first, size_t count, uint32_t word) override;
    void* host(rt::Buffer buffer) override;
    const void* view(rt::Buffer buffer) const override;
    unsigned glBuffer(rt::Buffer buffer) const override;
    // A pool's rows kept on the GPU: the rules of rt::Memory's, a dispatch each
    // (gpu/gl_rows.cpp).
    void allocateRows(const rt::PoolRows& pool, size_t top, size_t highWater, size_t n, rt::Buffer out,
                      size_t outFirst) override;
    void releaseRows(const rt::PoolRows& pool, rt::Buffer killed, size_t killedAt, uint32_t base, rt::Buffer map,
                     size_t mapFirst) override;
    void markFresh(const rt::PoolRows& pool, rt::Buffer rows, size_t first, size_t count) override;
    void subStepClocks(rt::Buffer created, rt::Buffer mask, rt::Buffer step, rt::Buffer now, rt::Buffer dt, rt::Buffer length, size_t first,
                       size_t n, uint32_t k, uint32_t most, double t1, double limit) override;
    using rt::Memory::scatter;
    void scatter(std::span<const std::pair<rt::Buffer, rt::Buffer>> columns, size_t fromFirst, rt::Buffer rows,
                 size_t rowsFirst, size_t count) override;
    void identify(const rt::ObjectRuns& runs, size_t n, size_t kept, rt::Buffer created, rt::Buffer ids,
                  rt::Buffer mask, size_t first) override;
    void identifyRecords(rt::Buffer runs, size_t firstRecord, size_t records, size_t objects, rt::Buffer created,
                         rt::Buffer ids, size_t first) override;
    // Parents and their children on the GPU (gpu/gl_parents.cpp; parentsFromRecords
    // beside identifyRecords in gpu/gl_rows.cpp).
    void parentsFromRecords(rt::Buffer runs, size_t firstRecord, size_t records, size_t stride, rt::Buffer map,
                            size_t mapFirst, size_t objects, size_t kept, rt::Buffer parents, size_t first,
                            rt::Buffer readers) override;
    void gatherThrough(rt::Buffer from, rt::Buffer to, size_t toFirst, rt::Buffer rows, size_t rowsFirst,
                       size_t count) override;
    void gatherAlive(rt::Buffer alive, rt::Buffer to, size_t toFirst, rt::Buffer rows, size_t rowsFirst,
                     size_t count) override;
    void ancestorRows(rt::Buffer parents, rt::Buffer to, size_t toFirst, rt::Buffer rows, size_t rowsFirst,
                      size_t count) override;
    void gatherAge(rt::Buffer created, rt::Buffer frozenAt, rt::Buffer alive, rt::Buffer to, size_t toFirst,
                   rt::Buffer rows, size_t rowsFirst, size_t count, double now, rt::Buffer nowRows,
                   size_t nowFirst) override;
    void stampDeaths(rt::Buffer killed, size_t killedAt, uint32_t base, rt::Buffer map, size_t mapFirst,
                     rt::Buffer frozenAt, double t1, double dt, rt::Buffer created, rt::Buffer nows,
                     rt::Buffer lengths, size_t clocksFirst) override;
    void survivors(rt::Buffer mask, rt::Buffer killed, rt::Buffer out, size_t first, size_t count) override;
    void clearRows(const rt::PoolRows& pool, rt::Buffer killed, size_t killedAt, uint32_t base, rt::Buffer map,
                   size_t mapFirst) override;
    void appendKills(rt::Buffer killed, size_t killedAt, uint32_t base, rt::Buffer map, size_t mapFirst,
                     rt::Buffer into) override;
    void readersGone(rt::Buffer killed, size_t killedAt, uint32_t base, rt::Buffer map, size_t mapFirst,
                     rt::Buffer parents, rt::Buffer readers) override;
    void releaseUnread(const rt::PoolRows& pool, rt::Buffer killed, size_t killedAt, uint32_t base, rt::Buffer map,
                       size_t mapFirst) override;
    void releaseWaiting(const rt::PoolRows& pool, size_t rows) override;
    // Rate emissions decided on the GPU, a dispatch a site and one scan (gpu/gl_emission.cpp);
    // on the host where the emitters' rows are a few there.
    void emitAtRate(const rt::RateSites& sites, rt::Buffer runs) override;
    // The box around the drawn rows, reduced on the GPU (gpu/gl_bounds.cpp).
    rt::Bounds bounds(rt::Buffer visible, const std::array<rt::Buffer, 3>& position, const std::array<float, 3>& constant,
                      size_t rows) const override;

    // For the backend's launches. Whether the column's value is on the GPU.
    bool onDevice(rt::Buffer buffer) const;
    // Its GL buffer, holding the column's value (uploaded first when it is on the host).
    unsigned deviceBuffer(rt::Buffer buffer);
    // Its GL buffer for a dispatch that only reads rows [first, first + count): a column on
    // the host sends those rows alone, and stays the host's.
    unsigned deviceRows(rt::Buffer buffer, size_t first, size_t count);
    // The GPU wrote `count` rows from `first` into `words` (a GL buffer) at word `word`:
    // they become the column's, and the column's value is on the GPU from now on (timed as
    // `pass`).
    void adopt(rt::Buffer buffer, size_t first, size_t count, unsigned words, size_t word, const char* pass = "adopt");
    // The GPU wrote rows of the column in its own GL buffer (bound in place): its value is
    // on the GPU from now on.
    void written(rt::Buffer buffer);
    // mask[map[mapFirst + r]] = 0 for each r of `rows` (u8 mask, u32 map), where they are:
    // a launch the host side ran clears its kills in the alive mask through its batch's
    // row list on the GPU, which it need not read back (gpu/gl_rows.cpp).
    void clearMapped(rt::Buffer mask, std::span<const uint32_t> rows, rt::Buffer map, size_t mapFirst);
    // A GL buffer holding `rows` (sent once for every scatter, gather and launch that uses
    // the same list in a row: a creation batch's rows).
    unsigned rowList(std::span<const uint32_t> rows) const;
    // Sends every column's pending rows (scatters of a few rows from the host wait, to go
    // up together): before a launch binds anything, since sending them runs a dispatch of
    // its own (deviceBuffer sends a column's too, but mid-binding it would undo bindings).
    void flushPending();
    // Bytes of GL buffers held.
    size_t deviceBytes() const;
    // Bytes moved between the host and the GPU so far, either way (the backend adds its
    // launches' transfers).
    mutable uint64_t transferred = 0;
    // Times the host waited for the GPU to read something back (a read of a column on the
    // GPU; the backend adds its launches' read-backs): each one stalls the host until the
    // GPU has finished everything before it.
    mutable uint64_t waits = 0;
    // Compute dispatches so far: the backend's launches, and the scatters and gathers here.
    mutable uint64_t dispatches = 0;
    // Bytes launches copied on the GPU between columns and the launch's words, either way
    // (columns not bound in place: GlslBackend, adopt): memory traffic beyond the shader's.
    uint64_t staged = 0;
    // A scatter between columns on the host into a column of at most this many rows runs
    // on the host, and the column stays there (a small pool whose launches run on the
    // host: GlslBackend::setHostSide); 0: every scatter runs on the GPU.
    size_t hostRows = 0;
    // Where its work on the GPU is timed, by pass (the backend's; null: nowhere).
    PassTimer* timer = nullptr;
    static size_t wordsPerRow(rt::Elem e) { return e == rt::Elem::F64 ? 2 : 1; }
    // Pairs of columns one scatter dispatch moves (scatter by a row list in a buffer): two
    // storage blocks each, and the list's, of the 16 a compute shader has.
    static constexpr size_t kScatterColumns = 7;

private:
    struct Column;
    Column& at(rt::Buffer b) const;
    void toHost(Column& c) const;      // the column's value to the host copy
    void upload(Column& c) const;      // the host copy into the GL buffer (sized to the rows)
    // Rows of the host copy into the GL buffer, which may hold stale values elsewhere: for
    // a column read once on the GPU that stays the host's (a copy's or scatter's source).
    void uploadRows(Column& c, size_t first, size_t count) const;
    std::vector<std::unique_ptr<Column>> columns_;
    std::vector<uint32_t> free_;
    void runRows(unsigned program, unsigned from, unsigned to, size_t w, size_t first,
                 std::span<const uint32_t> rows, const char* pass) const;
    void runRows(unsigned program, unsigned from, unsigned to, size_t w, size_t first, unsigned list, size_t rowsAt,
                 size_t count, const char* pass) const;
    unsigned gatherProgram();  // (gather's, gatherThrough's: made on first use)
    void flush(Column& c) const;  // its pending rows to the GPU
    // A column an operation is about to write whole (its output, what it held not kept):
    // on the host, its value becomes the host copy's without a read-back; on the GPU, the
    // GL buffer's without an upload (its GL buffer, for the dispatch that writes it).
    void overwriteOnHost(rt::Buffer b);
    unsigned overwriteOnDevice(rt::Buffer b);
    void fillWords(Column& c, size_t first, size_t count, uint32_t word);
    std::vector<uint32_t> pendingColumns_;  // columns that may have rows pending
    // Scatters from the host of at most this many rows into a column on the GPU wait, and
    // go with the next ones once this many rows are pending (or the column is used).
    static constexpr size_t kPendingScatter = 64, kPendingFlush = 65536;
    mutable unsigned scatterProgram_ = 0, gatherProgram_ = 0, rowsBuffer_ = 0, paramsBuffer_ = 0, pendingBuffer_ = 0,
                     scatterColumnsProgram_ = 0;
    mutable unsigned uploadBuffer_ = 0;  // what the host sends into a column goes through it (sendThrough)
    // gpu/gl_rows.cpp: its programs (made on first use) and the runs' buffer.
    unsigned allocateProgram_ = 0, releaseProgram_ = 0, pushedProgram_ = 0, freshProgram_ = 0, identifyProgram_ = 0, runsBuffer_ = 0;
    unsigned bound(rt::Buffer b);  // deviceBuffer, for a column the dispatch writes
    bool allOnHost(std::initializer_list<rt::Buffer> buffers) const;
    void dispatchRows(unsigned program, size_t invocations);
    mutable std::vector<uint32_t> rowsSent_;  // what rowsBuffer_ holds
    mutable unsigned boundsProgram_ = 0, boxBuffer_ = 0;  // gpu/gl_bounds.cpp
    unsigned emitRowsProgram_ = 0, emitScanProgram_ = 0, metaBuffer_ = 0;  // gpu/gl_emission.cpp
    unsigned identifyRecordsProgram_ = 0, clearMappedProgram_ = 0, parentsProgram_ = 0, subStepProgram_ = 0;  // gpu/gl_rows.cpp
    // gpu/gl_parents.cpp
    unsigned gatherAliveProgram_ = 0, gatherAgeProgram_ = 0, stampDeathsProgram_ = 0, survivorsProgram_ = 0,
             readersGoneProgram_ = 0, releaseUnreadProgram_ = 0, releaseWaitingProgram_ = 0, clearRowsProgram_ = 0,
             appendProgram_ = 0, appendedProgram_ = 0, ancestorRowsProgram_ = 0;
    uint32_t killListGrid(rt::Buffer killed, size_t killedAt) const;
    void throughRows(unsigned& program, const char* shader, const char* name, rt::Buffer from, rt::Buffer to,
                     size_t toFirst, rt::Buffer rows, size_t rowsFirst, size_t count);
    void killListProgram(unsigned& program, const char* body, const char* name);
    void bindKillList(rt::Buffer killed, size_t killedAt, uint32_t base, rt::Buffer map, size_t mapFirst, uint32_t grid,
                      uint32_t mode = 0, std::array<uint32_t, 2> value = {}, uint32_t extra = 0);
    void bindScanBlocks(const rt::PoolRows& pool);
};

// A shader of the memory's operations (gpu/gl_rows.cpp, gl_parents.cpp): work groups of
// 64, the Params block, INVOCATION and RUN_WORDS defined, then `body`.
std::string operationShader(const std::string& body);

// Host rows to GPU words (u8 widened to a word) and back.
void toWords(const void* from, rt::Elem e, size_t rows, uint32_t* to);
void fromWords(const uint32_t* from, rt::Elem e, size_t rows, void* to);

}  // namespace psys::gpu
