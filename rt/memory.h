// Where a system's columns live, and the only way the run-time and the backends refer to
// them: a Buffer is a handle to one column of fixed-size elements on some memory (host
// RAM here; a GPU's memory for a GPU backend). Kernels are launched on buffers by handle
// (rt/backend.h); moving values between the host and a buffer is an explicit call
// (read, write), so where a device's memory is not the host's, every transfer is visible.
//
// HostMemory is the memory of the CPU backends (the interpreter and the LLVM JIT): its
// buffers are host arrays, and `host()` gives their address to the code that runs on the
// host (the backends' loops and the run-time's own bookkeeping of kills, emissions and
// creation).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "rt/allocation.h"
#include "rt/host_allocator.h"

namespace psys::rt {

enum class Elem : uint8_t { F32, F64, U32, U8 };
constexpr size_t elemSize(Elem e) { return e == Elem::F64 ? 8 : e == Elem::U8 ? 1 : 4; }

// In a scatter's row list: this element is not written.
constexpr uint32_t kSkipRow = std::numeric_limits<uint32_t>::max();

struct Buffer {
    uint32_t id = std::numeric_limits<uint32_t>::max();
    bool valid() const { return id != std::numeric_limits<uint32_t>::max(); }
    bool operator==(const Buffer&) const = default;
};

// A pool's rows in a memory (Memory::allocateRows): its free stack, each row's generation
// (u32 columns of the pool's rows) and its masks (u8).
// The box around what is drawn: the least and greatest of each position component over
// the drawn rows (empty where none is).
struct Bounds {
    std::array<float, 3> low{}, high{};
    bool empty = true;
    bool operator==(const Bounds&) const = default;
};

struct PoolRows {
    Buffer stack, generation, updatable, alive;
    // u32: the stack's top, where a release pushes (the memory's own count of it), then
    // the rows frozen for their readers (`waiting`).
    Buffer counters;
    // A pool whose objects children read (rt/system_state.cpp: a parent type whose rows
    // are in the memory beside its children's): per row, its children not freed yet
    // (u32), and whether it is frozen for them (u8: killed, neither alive nor updatable).
    Buffer readers, waiting;
    // Such a pool that is a child itself (a grandparent's child, read by its own children):
    // its rows' parents (u32, rt::kSkipRow for none) and its parent pool's readers, a row
    // freed by releaseUnread or releaseWaiting a reader less there (rt/ledger.h's rule).
    Buffer parents, parentReaders;
};
constexpr size_t kCounterTop = 0, kCounterWaiting = 1, kCounters = 2;

// A creation batch's objects as runs (rt/system_create.h, Creation::Run): object r of
// run u (first[u] <= r < first[u] + count[u], k = r − first[u]) has the id id[u] + k and
// the creation time firstTime[u] + ⌊k / perEvent[u]⌋ · spacing[u].
struct ObjectRuns {
    std::vector<uint32_t> first, count, id, perEvent;
    std::vector<double> firstTime, spacing;
    size_t size() const { return first.size(); }
    // The creation time of object k of run u: one rule for every memory.
    double time(size_t u, uint32_t k) const { return eventTime(firstTime[u], k, perEvent[u], spacing[u]); }
};

// A type's rate emit sites (and bursts) over rows [0, rows) of its columns
// (Memory::emitAtRate).
struct RateSites {
    struct Site {
        Buffer rate, count;  // f32 per row; invalid: rateValue, countValue every row's
        float rateValue = 0, countValue = 1;
        Buffer accumulated;  // f64 per row: events accumulated, in [0, 1) (a rate's)
        // Objects its target may still take (its free rows less those queued): the room of
        // every site of its group.
        uint32_t room = 0;
        // Its group: the first site into the same target (its own index where none before
        // it is). A group's sites share its room, their objects one run: placed in row
        // order, a row's sites in order, as the host queues them one emitter at a time.
        uint32_t group = 0;
        // What it emits (rt/emission.h): at a rate (rows the update killed emit nothing); a
        // burst in the update (rt::burst: `count` objects at t1 from each row of the mask,
        // killed ones too — a death's or an edge's: the update yields 0 where nothing
        // fired); a burst at creation (`count` objects at each row's creation time, from
        // `created`). Only a rate moves its accumulator.
        enum class Kind : uint8_t { Rate, Burst, AtCreation };
        Kind kind = Kind::Rate;
    };
    std::vector<Site> sites;  // in the type's order of sites
    size_t rows = 0;
    size_t first = 0;  // the rows are [first, first + rows) of every column (records from 0)
    Buffer mask;     // u8: the rows that emit
    Buffer killed;   // u8: rows the update killed (they emit at no rate); invalid: none
    Buffer created;  // f64: where given, row r's update began at created[r] (a batch's first), else at t1 − dt
    // f64, both or neither: where given, row r's update is the sub-step that ends at now[r]
    // and lasts length[r] (a batch's first update in sub-steps: Memory::subStepClocks) —
    // its rate over that, its bursts in the update at now[r]; `created` then only places
    // the bursts at creation.
    Buffer now, length;
    bool fresh = false;  // the rows' objects were just created: their accumulators start at 0 (not read)
    double dt = 0, t1 = 0;
    uint32_t nextId = 0;  // the first id the emissions take
    // One window of a larger operation (Memory::emissionWindow): where valid, the runs of
    // the window before it over the rows just before these (the same sites, rooms and
    // next id), whose totals start at word `carryAt` (runsTotalsAt of its rows). These rows
    // go on from them: each group's room as that window left it, the ids after its, and
    // its totals added to these (so the last window's are the whole operation's); places
    // (a record's words 0 and kRunSitePlace) start again at 0, among this window's objects.
    Buffer carry;
    size_t carryAt = 0;
};

// Where emitAtRate's records are: a group's records one range, in row order and a row's
// sites in order (so their places rise with the record), the groups in the order of
// their first sites. Site s's record for row r is first[s] + r · stride[s] (stride: the
// sites of its group); group g's range starts at first[g] (its first site's rank is 0).
struct RecordLayout {
    std::vector<size_t> first, stride;
    explicit RecordLayout(const RateSites& sites);
    size_t record(size_t site, size_t row) const { return first[site] + row * stride[site]; }
};

// Emitter rows' records in a runs buffer (Memory::emitAtRate), kRunWords words each, in
// rt::ObjectRuns' form: first (the run's first object's place among its group's objects),
// count, id, perEvent, firstTime (f64, low word first), spacing (f64), then its first
// object's place among its own site's objects (for the site's spawn launch); after the
// records (rows · sites of them, where RecordLayout says), the totals: the emissions'
// invalid rates and counts, the counts clamped, the ids taken; then per site: objects
// kept, and objects asked for (u64, low word first) — so that one read brings back all
// the host needs.
constexpr size_t kRunWords = 9;
constexpr size_t kRunSitePlace = 8;
constexpr size_t kTotalsInvalid = 0, kTotalsClamped = 1, kTotalsIds = 2, kTotalsSites = 3, kTotalsPerSite = 3;
// The words of a runs buffer for `rows` emitters at `sites` sites, and where its totals start.
constexpr size_t runsTotalsAt(size_t rows, size_t sites) { return rows * sites * kRunWords; }
constexpr size_t runsWords(size_t rows, size_t sites) {
    return runsTotalsAt(rows, sites) + kTotalsSites + kTotalsPerSite * sites;
}

class Memory {
public:
    virtual ~Memory() = default;
    // Where the host's memory comes from from now on (SystemOptions::allocator): the host
    // memory's columns made after it, and the host arrays of pools made after it
    // (Pool::Pool). What was made before goes back where it came from.
    void useAllocator(const HostAllocator& allocator) { allocator_ = allocator; }
    const HostAllocator& allocator() const { return allocator_; }
    // A column of `rows` elements, zero-filled.
    virtual Buffer create(Elem elem, size_t rows) = 0;
    // Keeps the first min(old, rows) elements; new ones are zero.
    virtual void resize(Buffer buffer, size_t rows) = 0;
    // Room for the `rows` rows a column may grow to (a pool's capacity): growing to them
    // later moves nothing and copies nothing. The host's memory takes the address space
    // now and no memory (no page is touched before its rows are used); a device's may do
    // nothing.
    virtual void reserve(Buffer, size_t) {}
    // The pages of the first `rows` rows of what reserve took given now (System::reserve),
    // so that filling them later faults no page in a step; a device's may do nothing.
    virtual void populate(Buffer, size_t) {}
    virtual void release(Buffer buffer) = 0;
    virtual size_t rows(Buffer buffer) const = 0;
    virtual Elem elem(Buffer buffer) const = 0;

    // Explicit transfers between the host and a buffer, `count` elements from row `first`.
    virtual void read(Buffer buffer, size_t first, size_t count, void* out) const = 0;
    virtual void write(Buffer buffer, size_t first, size_t count, const void* in) = 0;
    // Between buffers of one element type: to[toFirst + i] = from[fromFirst + i]; and
    // to[rows[i]] = from[fromFirst + i] (rows[i] == kSkipRow: nothing).
    virtual void copy(Buffer from, size_t fromFirst, Buffer to, size_t toFirst, size_t count) = 0;
    virtual void scatter(Buffer from, size_t fromFirst, Buffer to, std::span<const uint32_t> rows) = 0;
    // The other way: to[toFirst + i] = from[rows[i]], and 0 where rows[i] == kSkipRow
    // (children reading their parents' exports: the values are fetched where they live).
    virtual void gather(Buffer from, Buffer to, size_t toFirst, std::span<const uint32_t> rows) = 0;
    // Zeroes `count` elements from row `first`, where the buffer lives (a device memory
    // does not bring the column to the host for it, as `host` would).
    virtual void clear(Buffer buffer, size_t first, size_t count);
    // Sets `count` elements of a 4-byte column (f32, u32) from row `first` to the bits
    // `word`, where the buffer lives (a constant column: an empty neighbour fold).
    virtual void fill(Buffer buffer, size_t first, size_t count, uint32_t word);

    // The address of a buffer's first element where the host can address it, else null:
    // `host` for reading and writing, `view` for reading only (a memory that keeps
    // columns on a device brings the values to the host for either, and takes them as
    // changed after `host`).
    virtual void* host(Buffer buffer) = 0;
    virtual const void* view(Buffer buffer) const { return const_cast<Memory*>(this)->host(buffer); }
    // The OpenGL buffer object holding the column's value, on a memory that keeps columns
    // in GL buffers (a viewer draws straight from it); 0 on any other.
    virtual unsigned glBuffer(Buffer) const { return 0; }
    // Whether every buffer lives in the host's memory, `host` never moving anything: the
    // run-time may then keep its masks in the columns themselves (rt::SyncedMask).
    virtual bool hostResident() const { return false; }

    // A pool's rows kept where its columns are (Pool::keepRowsInMemory): the bookkeeping
    // of rows as operations on buffers, so that a device does it where the rows are and
    // the host keeps only counts. Each is written here once for any memory, by the rule
    // of rt/allocation.h (through `host`: the CPU's memories); a device's memory does the
    // same on the device (GlMemory: one dispatch each).
    //
    // Rows for objects k < n of a batch, out[outFirst + k] = FreeRows{stack, top,
    // highWater}.row(k) (n at most the room; the pool's columns already hold the rows);
    // each new row alive, not updatable; the stack's top in `counters` what is left of it.
    virtual void allocateRows(const PoolRows& pool, size_t top, size_t highWater, size_t n, Buffer out, size_t outFirst);
    // The rows a late launch killed, freed in order: `killed` holds their count at word
    // `killedAt`, then launch rows; launch row r is pool row base + r, or map[mapFirst + r]
    // where `map` is given (a batch's rows). Each is pushed onto the stack at the top
    // `counters` holds (the host need not know how many there are), its generation moved
    // on, its masks cleared; the top moves on.
    virtual void releaseRows(const PoolRows& pool, Buffer killed, size_t killedAt, uint32_t base, Buffer map,
                             size_t mapFirst);
    // The pool rows of such a kill list, in its order, read where they are (a reload's).
    std::vector<uint32_t> killedRows(Buffer killed, size_t killedAt, uint32_t base, Buffer map, size_t mapFirst) const;
    // A kill list's pool rows (as releaseRows reads it) appended to the list `into` (its
    // count, then pool rows: base 0, no map), in order: a step's sub-steps' kills gathered
    // into one list, at most a row each (a row dies once a step).
    virtual void appendKills(Buffer killed, size_t killedAt, uint32_t base, Buffer map, size_t mapFirst, Buffer into);
    // The rows of a kill list (as releaseRows reads it) neither alive nor updatable (where
    // `pool.updatable` is given), not freed yet: killed objects that wait for the step's end.
    virtual void clearRows(const PoolRows& pool, Buffer killed, size_t killedAt, uint32_t base, Buffer map,
                           size_t mapFirst);
    // The rows rows[first, first + count) become updatable where they are alive (the rows a
    // step created, at the next step's start).
    virtual void markFresh(const PoolRows& pool, Buffer rows, size_t first, size_t count);
    // Parents and children whose rows are both in the memory: a child pool holds its
    // parent's row in `parents` (u32 a row, rt::kSkipRow for none); the parent pool counts
    // its children not freed yet (PoolRows::readers) and keeps a killed object that has
    // some frozen (PoolRows::waiting) until they are gone (rt/ledger.h's rule).
    //
    // Objects r < objects of a batch from a group's records (identifyRecords' arguments;
    // `stride` records a row): parents[first + r] the pool row of its record's emitter —
    // map[mapFirst + j] for the j-th row of the records where `map` is given (an emitter
    // batch's rows), else mapFirst + j; and each of the first `kept` a reader more of it.
    virtual void parentsFromRecords(Buffer runs, size_t firstRecord, size_t records, size_t stride, Buffer map,
                                    size_t mapFirst, size_t objects, size_t kept, Buffer parents, size_t first,
                                    Buffer readers);
    // A parent's values through a child's `parents` rows, where they are: to[toFirst + i] =
    // from[rows[rowsFirst + i]], 0 where that is kSkipRow; `alive` (u8) into an f32 column
    // as 1 or 0 (a child's `parent.alive`).
    virtual void gatherThrough(Buffer from, Buffer to, size_t toFirst, Buffer rows, size_t rowsFirst, size_t count);
    virtual void gatherAlive(Buffer alive, Buffer to, size_t toFirst, Buffer rows, size_t rowsFirst, size_t count);
    // One level further up: to[toFirst + i] = parents[rows[rowsFirst + i]] (u32), kSkipRow
    // where that is kSkipRow — a grandchild's grandparents' rows through its parents' rows
    // and its parent pool's `parents`.
    virtual void ancestorRows(Buffer parents, Buffer to, size_t toFirst, Buffer rows, size_t rowsFirst, size_t count);
    // A child's `parent.age` through its `parents` rows: to[toFirst + i] = ageAt(clock,
    // created[p]) (rt/clock.h) for p = rows[rowsFirst + i], the clock `now` — or
    // nowRows[nowFirst + i] where given (a batch's per-row clocks) — where the parent is
    // alive, else its death's (frozenAt[p], f64: the time of its last values); 0 where p
    // is kSkipRow.
    virtual void gatherAge(Buffer created, Buffer frozenAt, Buffer alive, Buffer to, size_t toFirst, Buffer rows,
                           size_t rowsFirst, size_t count, double now, Buffer nowRows, size_t nowFirst);
    // A parent pool's kill list (as releaseRows reads it): each row's death, the time of its
    // last values, into frozenAt — t1 − dt, or t1 − (t1 − created[row]) where `created` is
    // given (a batch's first update, from each object's creation), or where `nows` is given
    // nows[j] − lengths[j] (f64) for j = clocksFirst + mapFirst + r, launch row r of the list
    // (a batch's sub-step: each object's own clock), as the host computes it.
    virtual void stampDeaths(Buffer killed, size_t killedAt, uint32_t base, Buffer map, size_t mapFirst,
                             Buffer frozenAt, double t1, double dt, Buffer created, Buffer nows = {},
                             Buffer lengths = {}, size_t clocksFirst = 0);
    // Sub-step k (from 1) of a batch's first update, by rt/clock.h's rule, for rows
    // [first, first + n): each object's subStepCount(t1 − created, limit) sub-steps over
    // its span; step[r] (u8) = k ≤ its sub-steps and, for k = 1, mask[r], after that
    // step[r] itself (what the last sub-step killed cleared there: clearRows); where
    // set, now[r] (f64) = subStepEnd and dt[r] (f32) = span / sub-steps, and where
    // `length` is given length[r] (f64) = span / sub-steps unrounded (an emitter's rate
    // rule reads it: RateSites::length). No object may take more than `most` (the host's
    // bound: it does not know the creation times; a device clamps there, the host throws).
    virtual void subStepClocks(Buffer created, Buffer mask, Buffer step, Buffer now, Buffer dt, Buffer length,
                               size_t first, size_t n, uint32_t k, uint32_t most, double t1, double limit);
    // out[first + i] = mask[first + i] && !killed[first + i] (u8): the rows an update left
    // alive, whose exports it computes.
    virtual void survivors(Buffer mask, Buffer killed, Buffer out, size_t first, size_t count);
    // The rows of a child pool's kill list (as releaseRows reads it), freed: each a reader
    // less of its parent (`parents`: the child pool's; `readers`: the parent pool's).
    virtual void readersGone(Buffer killed, size_t killedAt, uint32_t base, Buffer map, size_t mapFirst,
                             Buffer parents, Buffer readers);
    // A parent pool's kill list freed as releaseRows frees it, but for rows some child
    // still reads: those are frozen instead (waiting, neither alive nor updatable,
    // counted in the counters), in the list's order the others pushed. Where the pool has
    // parents (PoolRows::parents), each row pushed is a reader less of its parent.
    virtual void releaseUnread(const PoolRows& pool, Buffer killed, size_t killedAt, uint32_t base, Buffer map,
                               size_t mapFirst);
    // The pool's waiting rows among [0, rows) whose readers are all gone, freed in row order
    // (each a reader less of its parent, likewise).
    virtual void releaseWaiting(const PoolRows& pool, size_t rows);
    // For each pair (from, to) of `columns`: to[rows[rowsFirst + i]] = from[fromFirst + i],
    // i < count, with the rows in a buffer (a batch's columns into its pool rows at once).
    virtual void scatter(std::span<const std::pair<Buffer, Buffer>> columns, size_t fromFirst, Buffer rows,
                         size_t rowsFirst, size_t count);
    // A creation batch's objects r < n from their runs (rt::ObjectRuns): mask[first + r] =
    // r < kept, and created[first + r], ids[first + r] for the objects of the runs (those
    // of a site's records are identifyRecords').
    virtual void identify(const ObjectRuns& runs, size_t n, size_t kept, Buffer created, Buffer ids, Buffer mask,
                          size_t first);
    // The rate emissions of emitter rows (rt/emission.h's rule, in row order, a row's sites
    // in order): each row of `sites.mask` not killed advances its accumulators and asks
    // for its events' objects; a site's target keeps them while its group's room lasts
    // (the rest dropped, counted in the totals), and the kept take ids from nextId in row
    // order, sites in order. Row r's run at site s is record RecordLayout::record(s, r) of
    // `runs` (u32, runsWords(rows, sites) of them: kRunWords a record, a row that emits
    // nothing has count 0), the totals after the records (kTotals…): `runs` is its output
    // only — what it held before, and its words past runsWords, are not kept (a scratch
    // buffer). Written here through `host`; a device does it where the rows are (GlMemory:
    // a dispatch a site and one scan, unless the rows are a few on the host).
    virtual void emitAtRate(const RateSites& sites, Buffer runs);
    // The most rows of `sites` emitters one emitAtRate takes: a larger operation runs as
    // windows of rows, each carrying on from the one before (RateSites::carry), so that
    // neither the words of a window's runs nor the rows of a column it reads pass
    // maxBlockBytes (nor 2³¹ bytes).
    size_t emissionWindow(size_t sites) const;
    // The largest buffer (or range of one) an operation of this memory binds, in bytes: a
    // device's largest storage block (GL_MAX_SHADER_STORAGE_BLOCK_SIZE: 128 MiB on
    // llvmpipe; the backend sets it), unlimited on the host, lowered by tests to a few rows.
    size_t maxBlockBytes = SIZE_MAX;
    // Objects r < objects of a batch from a group's records of `runs` (emitAtRate's,
    // records [firstRecord, firstRecord + records): the objects the record's count says
    // from its first on): created[first + r] and ids[first + r], where the records are.
    virtual void identifyRecords(Buffer runs, size_t firstRecord, size_t records, size_t objects, Buffer created,
                                 Buffer ids, size_t first);
    // The box around rows [0, rows) whose `visible` (f32) is 1: each position component's
    // least and greatest, from its column (f32), or `constant[c]` where it has none (an
    // invalid buffer). Min and max are exact, so the box is the same whatever the order
    // the rows are taken in (but for the sign of a zero; drawn values are finite). Written here through `view`; a device's memory reduces
    // where the columns are (GlMemory: a dispatch, 24 bytes back).
    virtual Bounds bounds(Buffer visible, const std::array<Buffer, 3>& position, const std::array<float, 3>& constant,
                          size_t rows) const;

private:
    HostAllocator allocator_;
};

// Host RAM: buffers are arrays the host addresses directly (aligned to 64 bytes).
class HostMemory final : public Memory {
public:
    HostMemory();
    ~HostMemory() override;
    Buffer create(Elem elem, size_t rows) override;
    void resize(Buffer buffer, size_t rows) override;
    void reserve(Buffer buffer, size_t rows) override;
    void populate(Buffer buffer, size_t rows) override;
    void release(Buffer buffer) override;
    size_t rows(Buffer buffer) const override;
    Elem elem(Buffer buffer) const override;
    void read(Buffer buffer, size_t first, size_t count, void* out) const override;
    void write(Buffer buffer, size_t first, size_t count, const void* in) override;
    void copy(Buffer from, size_t fromFirst, Buffer to, size_t toFirst, size_t count) override;
    void scatter(Buffer from, size_t fromFirst, Buffer to, std::span<const uint32_t> rows) override;
    void gather(Buffer from, Buffer to, size_t toFirst, std::span<const uint32_t> rows) override;
    void* host(Buffer buffer) override;
    bool hostResident() const override { return true; }
    // Bytes held by every live buffer (their capacity).
    size_t bytes() const;

private:
    struct Column;
    std::vector<std::unique_ptr<Column>> columns_;
    std::vector<uint32_t> free_;
};

// Typed access to a host-addressable buffer (null when the memory is not the host's).
template <typename T>
T* hostData(Memory& memory, Buffer b) {
    return static_cast<T*>(memory.host(b));
}
template <typename T>
const T* viewData(const Memory& memory, Buffer b) {
    return static_cast<const T*>(memory.view(b));
}

}  // namespace psys::rt
