// One pool per object type: structure of arrays, one f32 column per component of every
// state slot, parameter and export the IR keeps, plus the columns every object has
// (creation time, id) — all buffers in the backend's memory — and the bookkeeping the
// run-time keeps on the host (which rows are free, generations, parents, readers).
//
// Rows are reused through a free list; a Handle is (row, generation), and a row's
// generation changes whenever it is freed, so a stale handle never reads a reused row.
// A killed object that children still read stays in its row, frozen (not updated, not
// drawn, its exports kept) until its last reader is gone.
//
// A pool may keep its rows in the memory of its columns instead (keepRowsInMemory: the
// objects of a type that only die, emitters whose emissions the memory decides, children
// and their parents, on a device): the free stack, the generations and the masks are
// buffers there — and a child's parent rows, a parent's readers and frozen rows —
// changed by the memory's operations (rt::Memory::allocateRows), and the host keeps the
// counts — the stack's top, the high-water mark, the live count — which are all a step
// needs. The rows' statuses, generations, free stack and parents are read back when
// asked (tests, hot reload), not kept on the host.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <vector>

#include "core/function_ref.h"
#include "ir/ir.h"
#include "ir/value.h"
#include "rt/allocation.h"
#include "rt/host_array.h"
#include "rt/memory.h"

namespace psys::rt {

struct Handle {
    uint32_t row = std::numeric_limits<uint32_t>::max();
    uint32_t generation = 0;
    bool valid() const { return row != std::numeric_limits<uint32_t>::max(); }
};

enum class Status : uint8_t { Free, Alive, Frozen };

// A u8 column the host keeps and changes row by row, and a backend reads whole: the host's
// copy is the truth, and the rows changed since the last sync reach the column as one
// scatter (so the column may live on a device and a step moves only what changed). In a
// memory the host addresses (Memory::hostResident) the column is the host's copy itself:
// nothing to list or sync.
class SyncedMask {
public:
    void create(Memory& memory);
    void release(Memory& memory);
    void grow(Memory& memory, size_t rows);
    void reserved(Memory& memory);  // after Memory::reserve of the column
    // The column is the host's copy itself: rows may be set from several threads at once
    // (each row by one), nothing being listed.
    bool direct() const { return resident_; }
    void set(uint32_t row, uint8_t value) {
        uint8_t* h = data();
        if (h[row] == value) return;
        h[row] = value;
        if (!direct_) changed_.push_back(row);
    }
    const uint8_t* host() const { return direct_ ? direct_ : host_.data(); }
    void sync(Memory& memory);
    void restore(Memory& memory, std::vector<uint8_t> values);  // every row at once
    Buffer column;

private:
    uint8_t* data() { return direct_ ? direct_ : host_.data(); }
    uint8_t* direct_ = nullptr;      // the column, where the host addresses it
    bool resident_ = false;          // the memory is the host's
    std::vector<uint8_t> host_;      // else the host's copy,
    std::vector<uint32_t> changed_;  // the rows changed since the last sync,
    Buffer staging_;                 // and their values, for the scatter
};

// Typed values as component columns: value i's component c is column(i, c).
class ValueColumns {
public:
    void define(Memory& memory, const std::vector<ir::Type>& types, size_t rows);
    void release(Memory& memory);
    void resize(Memory& memory, size_t rows);
    size_t count() const { return types_.size(); }
    const ir::Type& type(size_t i) const { return types_[i]; }
    Buffer column(size_t i, size_t component) const { return columns_[offset_[i] + component]; }
    // One value of one row, through explicit transfers.
    ir::Value get(const Memory& memory, size_t i, size_t row) const;
    void set(Memory& memory, size_t i, size_t row, const ir::Value& v) const;

private:
    std::vector<ir::Type> types_;
    std::vector<size_t> offset_;
    std::vector<Buffer> columns_;
};

class Pool {
public:
    Pool(const ir::Object& object, size_t capacity, Memory& memory);
    ~Pool();
    Pool(Pool&&) noexcept;
    Pool(const Pool&) = delete;
    Pool& operator=(const Pool&) = delete;
    Pool& operator=(Pool&&) = delete;

    const ir::Object& object() const { return *object_; }
    size_t capacity() const { return capacity_; }
    size_t rows() const { return inMemory_ ? highWater_ : status_.size(); }  // the high-water mark
    size_t live() const {
        counted();
        return live_;
    }
    size_t frozen() const {
        counted();
        return frozen_;
    }
    size_t free() const { return capacity_ - live() - frozen(); }
    // At least the live objects, as the host last counted them: without asking the memory
    // for counts it owes (a step's kills not counted yet only make it more).
    size_t liveAtMost() const { return live_; }

    // Rows for `n` new objects at once, by the allocation rule (rt/allocation.h): rows[k]
    // for the k-th, kSkipRow for those past capacity; returns how many got one.
    size_t allocate(size_t n, uint32_t* rows);
    void release(uint32_t row);  // back to the free list; the generation moves on
    // Lists of distinct rows taken as one list, in order: a launch's kill lists, one a chunk.
    using RowLists = std::span<const std::span<const uint32_t>>;
    static size_t rowCount(RowLists lists) {
        size_t n = 0;
        for (std::span<const uint32_t> list : lists) n += list.size();
        return n;
    }
    // Objects that died alive and nobody reads, freed at once (no frozen state between):
    // onto the free stack in the order given, each row's generation moved on.
    void releaseKilled(RowLists lists);
    void releaseKilled(std::span<const uint32_t> rows) { releaseKilled(RowLists(&rows, 1)); }
    // The frozen rows of `lists` (of a type nobody reads) freed, onto the stack in order.
    void releaseFrozen(RowLists lists) { frozen_ -= releaseRows(lists, Status::Frozen); }
    void freeze(uint32_t row, double at);  // `at`: the time of its last values; its age stays what it was then
    // freeze of each row, `at[k]` the k-th row's time (or at[0] every row's).
    void freeze(RowLists lists, std::span<const double> at);
    void freeze(std::span<const uint32_t> rows, std::span<const double> at) { freeze(RowLists(&rows, 1), at); }
    // How the bookkeeping of many rows at once runs (allocate, beginStep, freeze of many,
    // releaseKilled): `run(pieces, piece)` calls piece(p) for every p < pieces, on every thread
    // (System's executor). Each row is written by one piece and what goes in order (the
    // free stack) goes at places a count of each piece gives, so the results are the same
    // bits on any number of threads. Unset: in order on this thread.
    using PieceRunner = std::function<void(size_t, core::FunctionRef<void(size_t)>)>;
    void runPiecesWith(PieceRunner run) { runPieces_ = std::move(run); }
    bool matches(Handle h) const {
        fetch();
        return h.row < rows() && generation_[h.row] == h.generation && status_[h.row] != Status::Free;
    }
    Handle handle(uint32_t row) const { return {row, generations()[row]}; }
    Status status(uint32_t row) const {
        fetch();
        return status_[row];
    }

    // The rows kept in the memory (see above): from now on, before any object is created.
    // `child`: its objects' parents are in the memory too (parentRows); `read`: children
    // whose rows are there read its objects (PoolRows::readers, waiting).
    void keepRowsInMemory(bool child = false, bool read = false);
    // A child that is read (both): its frees count its parents' readers down, in the
    // parent pool's `parentReaders` (PoolRows::parents).
    void countsDownParent(Buffer parentReaders);
    bool rowsInMemory() const { return inMemory_; }
    // Rows for `n` objects of a batch by the allocation rule, in the memory: into
    // out[outFirst + k] for the first min(n, free()) of them; returns how many got one.
    // Every release before it must be counted (released).
    size_t allocate(size_t n, Buffer out, size_t outFirst);
    // A late launch's kills (their count, then launch rows, in `killed` from word
    // `killedAt`: rt::Memory::releaseRows) freed in the memory, onto the stack in order;
    // the host counts them when it learns how many there were (released: once, or once a
    // list `lists` gathered: Ledger::takeOut).
    void release(Buffer killed, size_t killedAt, uint32_t base, Buffer map, size_t mapFirst, size_t lists = 1);
    void released(size_t count);
    // A pool that children read (keepRowsInMemory's `read`): its kills freed where nobody
    // reads them, the others frozen (Memory::releaseUnread); its frozen rows whose readers
    // all went freed (Memory::releaseWaiting); the host's counts — the stack's top, the
    // frozen, the live — read from the memory's own once such releases are done
    // (countFromMemory), when the host next asks for them: a step that creates none of its
    // objects and a host that asks for no stats wait for nothing.
    void releaseUnread(Buffer killed, size_t killedAt, uint32_t base, Buffer map, size_t mapFirst);
    void releaseWaiting();
    void countFromMemory();
    // The host's bookkeeping of rows into the memory, whole (hot reload: rt/reload.cpp,
    // after parents and readers were counted again and the unread frozen freed).
    void uploadRows();
    const PoolRows& memoryRows() const { return rows_; }
    // The rows of a batch just allocated (rows[0, count)), made updatable at the next step's
    // start; the buffer is the pool's from then on (a scratch one: scratchRows).
    void createdRows(Buffer rows, size_t count);
    // A u32 buffer of at least `n` rows the pool keeps for a step's lists of rows (a batch's
    // rows, a launch's kills), and back to it once used.
    Buffer scratchRows(size_t n);
    // One holder fewer of a scratch buffer: back to the spare ones once none holds it.
    void recycle(Buffer b);
    // A second holder of a batch's rows (createdRows): its late kills, freed through them
    // at a step's end — for a trigger's batch, the next step's, after that step's start has
    // marked the rows fresh and let them go.
    void holdRows(Buffer rows) { held_.push_back(rows); }

    // Columns in the backend's memory.
    Buffer created, ids;             // f64, u32
    Buffer parentRows;               // u32: a child's parent's row, where both keep their rows in the memory
    Buffer frozenAt;                 // f64: such a parent's death (diedAt), where its children read its age
    // u8 masks, kept by the host and synced (syncMasks) before a launch over the pool:
    // `updatable`, the rows a step updates (alive, not created during it); `alive`, the
    // rows alive (what is drawn is among them).
    SyncedMask updatable, alive;
    const uint8_t* mask() const {
        if (!inMemory_) return updatable.host();
        fetch();
        return mask_.data();
    }
    void syncMasks();
    void restoreMask(std::vector<uint8_t> mask);  // hot reload: the whole update mask
    ValueColumns state, params, exports;  // params: only the kept ones
    // The neighbour folds (ir::Object::folds) of this step, per row below foldRows, and at
    // row foldRows what a fold is over nothing: what an object created since reads
    // (rt/neighbours.cpp).
    ValueColumns folds;
    size_t foldRows = 0;
    std::vector<int> paramColumn;    // per parameter: its value in `params`, or -1

    // Host bookkeeping (where the rows are in the memory, parentRows and
    // PoolRows::readers hold the parents and readers; these are a reload's copies).
    HostArray<Handle> parent;
    HostArray<uint32_t> readers;     // children that read this object live
    HostArray<double> diedAt;        // a frozen object's time of its last values
    // The time a child reading `row`'s age reads it at: `now`, or its death for a frozen
    // object (frozen with its last values, its age too).
    double ageClock(uint32_t row, double now) const { return status_[row] == Status::Frozen ? diedAt[row] : now; }
    std::vector<uint32_t> fresh;     // rows created during the current step (rows on the host)
    std::vector<uint32_t> freshRows() const;  // those rows, wherever the rows are kept
    void beginStep();                // the rows created before this step become updatable
    // Per emit site (f64 per row): the events a rate site accumulated, in [0, 1) — where the
    // rows are, so a memory that decides emissions (Memory::emitAtRate) moves them on there.
    std::vector<Buffer> emitted;

    Memory& memory() const { return *memory_; }
    // Rebuilds the host bookkeeping of rows as given (hot reload, rt/reload.cpp).
    void restore(std::span<const Status> status, std::span<const uint32_t> generation, std::span<const uint32_t> freeRows);
    const HostArray<uint32_t>& generations() const {
        fetch();
        return generation_;
    }
    const HostArray<uint32_t>& freeRows() const {
        fetch();
        return freeRows_;
    }
    // The bytes one row of `object`'s pool takes: its columns (creation time, id, update
    // mask, kept state, kept parameters, exports) and the host's bookkeeping of it.
    static size_t rowBytes(const ir::Object& object);
    // Grows every column to `rows` rows (new rows free).
    void grow(size_t rows);
    // The rows its columns and host arrays have room for (reservableRows of its capacity):
    // a scratch column over its rows takes as much (Scratch::at), so it never moves either.
    size_t room() const { return room_; }
    // The pages of its first `rows` rows (at most its room) given now: System::reserve.
    void populate(size_t rows);

private:
    const ir::Object* object_;
    size_t capacity_;
    size_t room_ = 0;
    Memory* memory_;
    // On the host, or (rows in the memory) what was last read back: fetch().
    mutable HostArray<Status> status_;
    mutable HostArray<uint32_t> generation_;
    mutable HostArray<uint32_t> freeRows_;
    mutable size_t live_ = 0, frozen_ = 0;
    // The rows in the memory: its buffers and the host's counts; what changed them since
    // the host copies were read back (a version each change, the one read back).
    bool inMemory_ = false;
    PoolRows rows_;
    mutable size_t top_ = 0, highWater_ = 0, uncounted_ = 0;
    mutable bool countPending_ = false;  // (countFromMemory: read when asked)
    void counted() const;
    struct FreshRows {
        Buffer rows;
        size_t count;
    };
    std::vector<FreshRows> freshRows_;
    std::vector<Buffer> spare_;
    std::vector<Buffer> held_;  // (holdRows: one entry a second holder)
    uint64_t version_ = 0;
    mutable uint64_t fetched_ = 0;
    mutable std::vector<uint8_t> mask_;
    void fetch() const;  // the host copies of the rows in the memory, where they are stale
    void reserveRows();
    // Room for n rows in every column and host array (grow's first half: it may fail and
    // changes no row count).
    void roomFor(size_t n);
    // f(column) for each valid column a row has (bookkeeping, emitters' accumulators, state,
    // parameters, exports): what reserveRows and populate take room for.
    void forEachRowColumn(core::FunctionRef<void(Buffer)> f) const;
    PieceRunner runPieces_;
    // fn(begin, end) over pieces of [0, n): on every thread where runPieces_ is set and the
    // masks are the host's (SyncedMask::direct), else in order.
    void forPieces(size_t n, core::FunctionRef<void(size_t, size_t)> fn) const;
    // Rows [first, first + count) of row lists taken as one list, the first of them at
    // lists[list][at]: a piece spans as many lists as it takes (a chunk's kill list is
    // often a few rows), so the pieces are detail::kHostRows rows whatever the lists.
    struct ListPiece {
        RowLists lists;
        size_t list, at, first, count;
        template <typename F>  // f(k, row) for each row, k its place in the lists taken as one
        void each(F&& f) const {
            for (size_t l = list, i = at, k = first; k < first + count; ++k, ++i) {
                while (i == lists[l].size()) ++l, i = 0;
                f(k, lists[l][i]);
            }
        }
    };
    // fn(p, piece) for the lists' pieces in order, on every thread as forPieces.
    void forListPieces(RowLists lists, core::FunctionRef<void(size_t, const ListPiece&)> fn) const;
    // forListPieces' pieces and releaseRows' places, kept from call to call (a step
    // allocates nothing); one call at a time.
    mutable std::vector<ListPiece> listPieces_;
    std::vector<size_t> pieceStarts_;
    std::vector<double*> accumulated_;  // allocate's
    // Frees the rows of `lists` (distinct) whose status is `from`, onto the stack in order.
    size_t releaseRows(RowLists lists, Status from);
    void restoreInMemory();
    void writeRows();
};

}  // namespace psys::rt
