// What the run-time asks of a backend: a contract a CPU and a GPU can both implement.
//
// The run-time (rt/system.h) decides everything about a system's objects: which kernels
// run, over which rows, at what time (rt/clock.h); it evaluates the kernels that run once
// per step or per trigger itself, on the host (start, triggers, the uniform kernels:
// ir::Evaluator). A backend is handed the rest as launches:
//   - RowsLaunch: a kernel (init, update, exports, render) over a range of rows of a
//     column table — buffers in the backend's memory, by handle (rt/memory.h);
//   - ChildrenLaunch: a spawn kernel for the children one object emits at once, writing
//     their arguments into buffers (several objects' at once: runChildren).
// A launch returns counts (how many rows it killed); every value stays in the buffers.
// Before the first launch of a system, `prepare` lists every launch shape it will ask for,
// so a compiling backend compiles them all at once.
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "ir/ir.h"
#include "ir/value.h"
#include "rt/clock.h"
#include "rt/columns.h"
#include "rt/memory.h"

namespace psys::rt {

using Value = ir::Value;

struct RowsLaunch {
    const ir::Object* object = nullptr;
    const ir::Kernel* kernel = nullptr;
    const ColumnLayout* layout = nullptr;
    std::span<const Buffer> columns;        // by layout position
    Buffer mask;                            // u8 per row: rows with 0 are left alone
    size_t begin = 0, end = 0;              // the rows
    Clock clock;
    const Value* externs = nullptr;
    const Value* uniforms = nullptr;        // uniform clock: the values of the kernel's uniform kernel
    const ir::Kernel* uniformKernel = nullptr;  // per-row clock: evaluated at each row's clock
    uint32_t seed = 0;
    uint32_t draw = 0;                      // draw.index #0 (the step, or kCreationDraw)
    // The run-time takes this launch's counts and kills later, by Backend::collect (at the
    // end of the step, or at the next one on a backend that clearsKilled): a backend on a
    // device may answer with a ticket instead of waiting for them. Asked only of launches
    // whose kernel emits nothing it must read back.
    bool late = false;
    // A late launch's pool `alive` mask, for a backend that clearsKilled: it clears the
    // rows killed there, on the device — launch row r is pool row aliveRows[r −
    // aliveRowsFirst] (a creation batch's), or r where aliveRows is empty.
    Buffer aliveMask;
    std::span<const uint32_t> aliveRows;
    size_t aliveRowsFirst = 0;
    Buffer aliveRowsBuffer;  // or those rows in a u32 buffer of the memory (a batch's rows kept there)
    // A late launch over a pool whose rows are in the memory (Pool::keepRowsInMemory): a
    // u32 buffer of end − begin + 1 rows for its kills — their count, then their rows less
    // `begin` — which the pool frees there (rt::Memory::releaseRows). A backend that lists
    // them says so (RowsResult::killsListed); else the run-time lists them from the rows
    // it is given.
    Buffer killList;
    // The update of a type whose emissions the memory decides (Memory::emitAtRate), or
    // whose survivors' exports it computes (Memory::survivors): its emission columns and
    // its kill flags (what they read) stay in the memory — a device does not send them
    // back, and keeps the flags there besides any kill list.
    bool emissionsStay = false;
};

struct RowsResult {
    size_t killed = 0;    // rows of the range whose kill flag the kernel set
    size_t unstable = 0;  // rows whose `unstable` yield was true (update kernels)
    // Render launches of a backend that marksDrawn(): rows drawn, and rows visible but
    // with a NaN or infinite position, colour or size (not drawn).
    size_t drawn = 0, nonFinite = 0;
    // The rows killed, in order, where the backend has them listed (valid until its next
    // launch: the GLSL backend compacts them on the GPU); else empty, and the run-time
    // finds them in the kill flags.
    std::span<const uint32_t> killedRows = {};
    // Non-zero: a late launch (RowsLaunch::late) whose counts and kills are not here yet:
    // Backend::collect(ticket) gives them.
    uint64_t ticket = 0;
    // The kills are listed in RowsLaunch::killList (killedRows stays empty: the host need
    // not see them), now or, with a ticket, by the time the launch is done.
    bool killsListed = false;
};

// What is drawn, one rule for every backend: a row of a render launch is drawn when it is
// in `mask` (alive), visible, and its position, colour and size are all finite; the
// visible column is rewritten to 1 or 0, and the rows drawn and those not drawn for a NaN
// or an infinity are added to `result`. The run-time applies it after the launches of a
// backend that does not mark drawn rows itself (Backend::marksDrawn), and the GLSL
// backend to the render launches its host side runs.
void markDrawn(Memory& memory, const RowsLaunch& launch, const uint8_t* mask, size_t begin, size_t end,
               RowsResult& result);

struct ChildrenLaunch {
    const ir::Object* object = nullptr;     // the emitter's type
    const ir::Kernel* spawn = nullptr;
    const ColumnLayout* layout = nullptr;   // of the spawn kernel
    std::span<const Buffer> columns;        // the emitter's columns, by layout position
    uint32_t row = 0;                       // the emitter's row
    // The spawn kernel's parent reads for the emitter; null in a launch from records,
    // whose emitters' are in its parent columns (at each one's row: eachEmitter).
    const Value* parents = nullptr;
    Clock clock;                            // uniform
    const Value* externs = nullptr;
    uint32_t seed = 0, draw = 0;
    uint32_t firstChild = 0;                // child k draws with draw.index #1 = firstChild + k
    size_t count = 0;
    std::span<const Buffer> args;           // per component of the created type's parameters
    size_t argsFirst = 0;                   // child k's arguments at row argsFirst + k
    // Or, where `records` is valid, the launches of one site's emitters as a rate emission
    // left them (Memory::emitAtRate), so that they need not come back to the host:
    // `recordCount` records, record k at `record` + k · `recordStride` (rt::RecordLayout),
    // of emitter row `rows`[rowsFirst + k] (row rowsFirst + k where `rows` is not valid),
    // its children at argsFirst plus its place among its group's (the record's word 0),
    // drawn from its first id (word 2) on, its clock's now the record's first time where
    // `nowFromRecords` (a burst at creation: each emitter's creation time), or emitter k's
    // nows[nowsFirst + k] (f64) where `nows` is valid (a new emitter's sub-step: its end, as
    // the host clocks it: Creation::killOrEmit); `count` is then
    // the children of all of them, `placed` those of their group (the argument rows
    // [argsFirst, argsFirst + placed) they write among), and `row` and `firstChild` are
    // not used.
    Buffer records, rows;
    size_t record = 0, recordCount = 0, recordStride = 1, rowsFirst = 0, placed = 0;
    bool nowFromRecords = false;
    Buffer nows;
    size_t nowsFirst = 0;
};

// A launch from records as one launch an emitter (those with children), read from the
// memory: how a backend that does not build them where the records are runs them. Each
// one's parent reads (a launch from records has them in its parent columns, at each
// emitter's row) go into `parents`, which the launches point into.
std::vector<ChildrenLaunch> eachEmitter(const Memory& memory, const ChildrenLaunch& launch, std::vector<Value>& parents);

// The folds of one neighbour group over every row of the folding type (rt/neighbours.cpp,
// docs/language.md "Neighbours"): each fold of the group, for each object in self.mask,
// over the objects in other.mask whose drawn position lies within the group's radius of
// its own, in the grid's order (the same on every backend: core/hash.h cellBucket).
struct FoldLaunch {
    const ir::Object* object = nullptr;  // the folding type
    const ir::Kernel* pair = nullptr;    // its group's pair kernel: the terms
    const ir::NeighbourGroup* group = nullptr;
    bool same = false;                   // over its own type: an object is not its own neighbour
    struct Side {
        size_t rows = 0;
        Buffer mask;                                 // u8: the objects that fold, or are folded over
        std::vector<std::array<Buffer, 4>> exports;  // per export, its components
    } self, other;
    // Per fold of the object (only the group's are written): self.rows + 1 rows, the last
    // what the fold is over nothing (core::emptyFold), as are the rows not in self.mask.
    std::vector<std::array<Buffer, 4>> results;
    const Value* externs = nullptr;
    size_t externCount = 0;
};

// One object's walk of a fold's grid: the buckets of the 27 cells around it (ascending,
// each once), the grid's bucket starts, its places' positions and rows, this object's
// position, the radius squared and the row that is not its own neighbour (kSkipRow: none);
// `scratch` has room for every place of the buckets. The layout compiled walks read
// (codegen_llvm/pair_function.cpp).
struct PairWalk {
    const uint32_t* buckets;
    const uint32_t* start;
    const float* x;
    const float* y;
    const float* z;
    const uint32_t* rows;
    uint32_t* scratch;
    uint32_t count;  // buckets
    uint32_t skip;
    float px, py, pz, radius2;
};

// A group's walk and terms for one object, compiled: every place of the walk's buckets, in
// order, whose position lies within the radius (dx² + dy² + dz² ≤ r², in that order of
// operations, as the run-time's walk tests it) and whose row is not `skip`, is a
// neighbour. `self` points at this side's export columns (export e's component c at 4e +
// c; `selfRow` its row), `other` at the other side's (the ones the terms read, in the
// grid's order: by place), `acc` at the group's folds' components (in fold order), each
// combined with every neighbour's terms in order (core/fold.h combine).
using PairFunction = void (*)(const float* const* self, const float* const* other, uint32_t selfRow,
                              const PairWalk* walk, const Value* externs, float* acc);
static_assert(sizeof(PairWalk) == 80 && offsetof(PairWalk, px) == 64, "the layout compiled walks read");

// Every launch shape a system will use, listed before its first step.
struct Plan {
    struct Rows {
        const ir::Object* object;
        const ir::Kernel* kernel;
        Clock::Source now, dt;
        // Whether its launches usually cover many rows (a pool; the objects a stream
        // creates every step): a compiler may spend less on the others (not vectorize).
        bool many = true;
    };
    std::vector<Rows> rows;
    struct Children {
        const ir::Object* object;
        const ir::Kernel* spawn;
    };
    std::vector<Children> children;
};

// What a backend says about itself: for `psysc run --timing --remarks` and the viewer.
struct BackendReport {
    std::string target;          // "interpreter", or the CPU the JIT compiles for
    size_t kernels = 0;          // functions compiled
    size_t cacheHits = 0;        // kernels found already compiled
    size_t fromDisk = 0;         // kernels whose machine code came from the disk cache
    double compileSeconds = 0;
    struct Remark {
        std::string loop;
        bool vectorized;
        std::string message;
    };
    std::vector<Remark> remarks; // what the compiler said about each loop
    std::vector<std::string> calls;  // the library functions compiled code calls (sorted, once each)
    // A backend whose memory is a device's (the GPU): so far, the times the host waited
    // for a read-back, the bytes moved between the host and the device, and the bytes
    // launches copied on the device beyond what their kernels move.
    bool device = false;
    uint64_t waits = 0, transferredBytes = 0, stagedBytes = 0;
    // Late launches' read-backs taken (RowsLaunch::late), and of them those the GPU had not
    // finished when the host took them (the host waited).
    uint64_t lateReads = 0, lateStalls = 0;
    // Launches a device backend ran on the host instead (small pools whose columns are
    // there: GlslBackend::setHostSide).
    uint64_t hostLaunches = 0;
};

class Backend {
public:
    virtual ~Backend() = default;
    virtual std::string name() const = 0;
    // Where the columns of the systems this backend runs live.
    virtual Memory& memory() = 0;
    // Called once per system, before any of its launches.
    virtual void prepare(const Plan&) {}
    // What `prepare` called on another thread could not do (a GL context is one thread's),
    // a part at a time, on the thread that runs the systems: what it can in about `seconds`
    // (at least one piece); true once all of `plan` is ready. A host that must not stall a
    // frame (the viewer, reloading) calls it once a frame until then. The default: nothing
    // is left (prepare works on any thread).
    virtual bool prepareSome(const Plan&, double) { return true; }
    // The module's kernels are about to be destroyed: a backend that keeps anything by a
    // kernel's address drops it here (a later kernel may get the same address).
    virtual void forget(const ir::Module&) {}
    virtual RowsResult run(const RowsLaunch& launch) = 0;
    virtual void run(const ChildrenLaunch& launch) = 0;
    // Children launches that may run together, in any order: each writes its own rows of
    // the arguments and reads what none of them writes (a step's emitters of a type, a
    // batch's bursts). A GPU runs a spawn kernel's launches as one dispatch.
    // The default runs each launch, one an emitter (eachEmitter) where it has records.
    virtual void runChildren(std::span<const ChildrenLaunch> launches);
    // The counts and kills of a late launch that answered with `ticket` (its killedRows
    // valid until the next launch or collect), once each ticket.
    virtual RowsResult collect(uint64_t ticket) {
        (void)ticket;
        return {};
    }
    // Whether a late launch's ticket can be collected without waiting now.
    virtual bool ready(uint64_t ticket) {
        (void)ticket;
        return true;
    }
    // Whether the kills of a late launch that answered with a ticket clear its aliveMask
    // on the device, which the backend's render launches read: what is drawn then leaves
    // them out before the run-time has taken them, and the run-time may take them at the
    // next step instead of waiting at the end of this one (Ledger::endStep).
    virtual bool clearsKilled() const { return false; }
    // Whether the pools of objects that only die should keep their rows in the memory
    // (Pool::keepRowsInMemory): where the memory is a device's, so that a step's
    // bookkeeping happens there and the host keeps counts.
    virtual bool keepsRowsInMemory() const { return false; }
    // Whether launches on disjoint rows may run on several threads at once.
    virtual bool concurrent() const { return false; }
    // The rows a launch over a pool covers at most: a chunk that stays in cache (and gives
    // several threads work) for the loops of a CPU; every row at once on a GPU, where a
    // launch costs a dispatch and its counts a wait for the GPU.
    virtual size_t chunkRows() const { return kRowsPerChunk; }
    // Whether render launches mark the rows drawn themselves: visible = 1 where the row is
    // in the mask, its point visible and every render value finite, else 0; counted in
    // RowsResult. Else the run-time does it on the host after the launch.
    virtual bool marksDrawn() const { return false; }
    // Whether a step should compute what is drawn while it updates (chunk by chunk, the
    // rows still in cache) when the host draws every step: true where launches run on the
    // host's memory; a GPU gains nothing from it and pays a dispatch per chunk.
    virtual bool rendersInStep() const { return true; }
    // A neighbour group's folds, all on the backend's side; false: the run-time folds on
    // the host (its grid), asking pairFunction for each object's walk and terms.
    virtual bool fold(const FoldLaunch&) { return false; }
    // A group's walk and terms compiled (PairFunction); null: the run-time walks the grid
    // and evaluates the pair kernel.
    virtual PairFunction pairFunction(const ir::Object&, const ir::Kernel&) { return nullptr; }
    virtual BackendReport report() const { return {}; }
};

}  // namespace psys::rt
