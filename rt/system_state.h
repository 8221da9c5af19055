// Internal to rt/: what the parts of a System share (rt/system*.cpp) — the module, the
// backend and its memory, the object store (pools and the bookkeeping of parents and
// deaths), time, externs, the uniform values, the stats — and the helpers they all use.
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <vector>

#include "ir/evaluate.h"
#include "rt/emission.h"
#include "rt/ledger.h"
#include "rt/parallel.h"
#include "rt/schedule.h"
#include "rt/system.h"

namespace psys::rt::detail {

// Buffers a part of the run-time reuses from launch to launch (kill flags, emission
// columns, gathered parent values, masks …), grown on demand.
class Scratch {
public:
    explicit Scratch(Memory& memory) : memory_(&memory) {}
    ~Scratch();
    Scratch(Scratch&& other) noexcept : memory_(other.memory_), buffers_(std::move(other.buffers_)) { other.buffers_.clear(); }
    Scratch(const Scratch&) = delete;
    Scratch& operator=(const Scratch&) = delete;
    // Buffer `index`, of `elem`, with at least `rows` rows, and room for `room` rows
    // (Memory::reserve: a pool's table takes its capacity, so it never moves as it grows).
    Buffer at(size_t index, Elem elem, size_t rows, size_t room = 0);

private:
    Memory* memory_;
    std::vector<Buffer> buffers_;
};

// What the run-time decided about one object type.
struct TypeInfo {
    int parentType = -1;         // the type of its parent, or -1
    double stepLimit = 0;        // @step: the longest update, or 0
    const ir::Kernel* init = nullptr;
    const ir::Kernel* update = nullptr;
    const ir::Kernel* exports = nullptr;
    const ir::Kernel* render = nullptr;
    std::vector<const ir::Kernel*> spawn;  // per emit site (null: no arguments)
    ColumnLayout updateLayout, exportsLayout, renderLayout;
    std::vector<ColumnLayout> spawnLayout;
    std::vector<size_t> emitTarget;    // per emit site: the type it creates
    // kills; creates in its updates (ir::EmitSite::inUpdate); bursts at its creation
    // (atCreation); creates in the update that kills an object (whenKilled)
    bool kills = false, updateEmits = false, bursts = false, emitsWhenKilled = false;
    bool read = false;                 // a type's objects read this type's live (its parent type)
    bool unstable = false;             // its update counts updates beyond the stability limit
    // What its updates give back — kills, the unstable count — may be taken at the end of
    // the step (LateKills): it emits nothing at a rate (or what it emits the memory
    // decides, reading its kill flags there: rowsInMemory), has no exports (or, with its
    // rows in the memory, its survivors' exports, computed from its kill flags there) and
    // nothing but children in the memory reads it, so no one else looks at its dead before
    // then.
    bool late = false;
    // Its pool keeps its rows in the memory (Pool::keepRowsInMemory): a type whose kills
    // are late, or that never dies — and emits nothing, or emits what the memory decides
    // (Memory::emitAtRate: at a rate, in bursts at creation, on edges and on deaths) — with
    // no parent, or a parent whose rows are there too, in sub-steps or not (decideRows,
    // rt/system_state.cpp, says which).
    bool rowsInMemory = false;
    // The state slots a creation batch zeroes before init: those init does not set (every
    // one where there is no init, or where it reads the state).
    std::vector<size_t> zeroedState;
    std::vector<bool> counted, rated;  // per emit site: whether the update yields its count, its rate
    std::array<bool, 4> drawn{};       // visible, position, colour, size: whether render yields it
};

// What a step drew of a type while it updated it (rt/system_draw.h, DrawnInStep).
struct DrawnInStep {
    bool on = false;      // this step draws the type as it goes
    bool updated = false; // its update is done: what is created after it is drawn at creation
    bool fresh = false;   // the render columns hold what the last step drew, every row
    size_t drawn = 0;
    uint64_t nonFinite = 0;
};

// Per type: the scratch buffers and column tables of its launches over the pool.
// runEmissions' vectors for one type (the host's path), kept from step to step: a
// steady-state step allocates nothing (tests/capi/allocation_test.cpp).
struct EmissionWork {
    std::vector<float> rate, count;            // a rate or count every row shares, by site
    std::vector<const float*> rates, counts;   // else its column, by site
    std::vector<double*> accumulated;          // Creation::accumulators
    struct Piece {                             // a piece of rows (kHostRows), on its thread
        std::vector<uint32_t> rows;            // the rows that emit or count something, in order
        std::vector<RateEmission> emissions;   // theirs, a site a row
        std::vector<float> rate, count;        // the row's
        std::vector<RateEmission> row;         // the row's emissions, by site
    };
    std::vector<Piece> pieces;
};

struct TypeWork {
    explicit TypeWork(Memory& memory)
        : update(memory), exports(memory), masks(memory), render(memory), spawnParents(memory) {}
    Scratch update, exports, masks, render;
    Scratch spawnParents;  // the spawn tables' parent columns, each site's its own (State::gatherSpawnParents)
    std::vector<Buffer> updateTable, exportsTable, renderTable;
    DrawnInStep inStep;
    std::vector<LateKills::Part> killed;  // per chunk: the rows that died, in order (or a late launch's ticket)
    Buffer taken;  // this step's earlier sub-steps' kills, gathered (Ledger::takeOut), once there are some
    // The update pass just run: whether it ran (a pool with live rows), its kills are late or
    // listed per chunk, its chunks.
    struct Pass {
        bool ran = false, late = false, listed = false;
        bool takeOut = false;  // its late kills taken out of the masks at once (an earlier sub-step's, in the memory)
        size_t chunks = 0;
        // Where the type creates as its objects die (TypeInfo::emitsWhenKilled): the rows
        // this pass killed, in row order (no longer updatable when its emissions run).
        std::vector<uint32_t> dying;
        // An emitter's sub-step kills, taken out after its emissions (its bursts on death
        // are from the rows they kill): runKills leaves them to runEmissions.
        std::optional<LateKills> untaken;
    } pass;
    std::vector<std::vector<Buffer>> spawnTables;  // per emit site: the pool's columns for its spawn kernel
    EmissionWork emission;
    // runKills': a piece's killed rows, and the pieces' (or chunks') lists handed to the
    // ledger, kept from step to step.
    std::vector<std::vector<uint32_t>> killPieces;
    std::vector<std::span<const uint32_t>> killLists;
    std::vector<double> killTimes;  // a scaled step's: each killed row's time, in the lists' order
};

// Per type and served kernel (update, render, exports): the uniform values and the
// (dt, time, externs) they were computed for.
struct UniformCache {
    bool valid = false;
    float dt = 0, time = 0;
    uint64_t externs = 0;
    std::vector<Value> values;
};

// An instance's slot in the table (core/instances.h, rt/system_instances.cpp): where it is
// in its life, and its generation — it changes when the instance finishes, so a handle
// of an earlier play reads "finished" however often the slot is played again.
struct InstanceSlot {
    InstanceLife life = InstanceLife::Finished;  // Finished: free
    uint32_t generation = 0;
    float speed = 1;      // System::setSpeed: seconds of its own a second of the system's
    bool paused = false;  // System::pause: a speed of 0 until resumed, its speed kept
};

// The host's neighbour fold's arrays (rt/neighbours.cpp), kept from step to step: fresh
// ones each step cost a page fault every 4 KiB of them.
struct FoldBuffers {
    std::vector<uint32_t> start, rows, order, orderStart, bucketOf;
    std::vector<float> x, y, z, results, column;
    std::vector<std::vector<float>> sorted;
};

struct State {
    State(ir::Module module, Backend& backend, SystemOptions options);
    ~State();

    ir::Module module;
    Backend& backend;
    Memory& memory;
    SystemOptions options;
    std::vector<Pool> pools;
    std::vector<TypeInfo> types;
    // The types, the most deeply nested first (a parent after its children: Ledger::release).
    std::vector<size_t> deepestFirst;
    std::vector<TypeWork> work;
    // The rows of ancestors further up than a parent (gatherThrough's), one launch's at a
    // time: the chunks of a pool's launch gather on several threads.
    Scratch ancestors;
    std::mutex ancestorsInUse;
    std::vector<Value> externs;  // the module's, then the instance table where it has one
    uint64_t externsVersion = 0;
    // Instances, by slot (slot 0: the system's own, played at the start), with the
    // instances that finished in the last step and a step's counts (kept for their vectors).
    std::vector<InstanceSlot> instances;
    std::vector<InstanceHandle> finishedInstances;
    std::vector<uint32_t> instanceLive;  // finishInstances: per slot, whether a live row was seen
    std::vector<size_t> poolOrder;       // finishInstances: the pools by size, where they are many
    // A slot's record (core/instances.h): its transform, then its values of the externs.
    size_t instanceValues() const { return core::instanceRecordValues(module.externs.size()); }
    Value* instanceRecord(size_t slot) { return externs.data() + module.externs.size() + 1 + instanceValues() * slot; }
    const Value* instanceRecord(size_t slot) const { return const_cast<State*>(this)->instanceRecord(slot); }
    // The table with room for `slots` slots (new ones free, their records the identity).
    void growInstances(size_t slots);
    // Where slot `slot` is in its life, and its record's flags, which follow from it
    // (emitting while playing; killed once killed or finished: nothing of it may live).
    void setLife(size_t slot, InstanceLife life);
    // The instances whose objects are all gone, after a step: finished (the CPU's pools).
    void finishInstances();
    // Instance speeds (rt/system_speeds.cpp): each slot's speed in the step being run (0
    // while paused), taken at its start, after the last step's deaths are settled —
    // whose times they give (Ledger) — and whether some slot runs at another speed than
    // 1 (a scaled step: each row's update gets its own dt); the fastest of them.
    std::vector<float> stepSpeeds;
    bool scaledStep = false;
    float fastest = 1;
    void takeSpeeds();
    // A row's speed, its instance's in this step: the instance column found once a call.
    struct RowSpeeds {
        const float* instance = nullptr;  // (none: every row at 1)
        const float* speeds = nullptr;
        uint32_t slots = 0;
        float operator()(uint32_t row) const;
    };
    RowSpeeds rowSpeeds(size_t type) const;
    float rowSpeed(size_t type, uint32_t row) const { return rowSpeeds(type)(row); }
    // A scaled step's update of `type` over (t1 − dt, t1], rows [begin, end) of its
    // updatable ones: each row's dt (its instance's speed times dt) into `dts`, and its
    // creation time moved on by (1 − speed) · dt, so that its age at t1 has grown by its
    // own dt (rt/system_speeds.cpp says why).
    void scaleRows(size_t type, double dt, float* dts, const uint8_t* updatable, size_t begin, size_t end);
    std::vector<std::array<UniformCache, 3>> uniformCache;
    std::vector<Value> uniformValues;  // (uniforms': kept from step to step)
    std::vector<TypeStats> typeStats;
    Stats stats;
    double now = 0;
    double lastDt = 0;
    uint64_t step = 0;
    uint32_t nextId = 0;
    bool started = false;
    bool saidFinished = false;  // SystemOptions::onFinished was called, and nothing came alive since
    // The start's emit sites a reload added — spawns of types the old start did not spawn —
    // run at the next start() (rt/reload.cpp).
    std::vector<size_t> reloadSpawns;
    Ledger ledger{*this};  // the deaths of the step (rt/ledger.h)
    ir::Evaluator evaluator;  // the kernels the run-time evaluates itself (start, triggers, uniform kernels)
    std::unique_ptr<Parallel> parallel;
    Schedule schedule;  // the phases of a step (rt/schedule.h)

    // The ancestor `depth` levels up of (type, row), or (-1, 0) when there is none.
    std::pair<int, uint32_t> ancestor(size_t type, uint32_t row, int depth) const;
    // The values of `kernel`'s uniform kernel at (dt, time), evaluated on the host and
    // cached until dt, time or an extern changes; null when it has none.
    const Value* uniforms(size_t type, const ir::Kernel& kernel, float dt, float time);
    // The uniform kernel serving `kernel`, if any.
    const ir::Kernel* uniformKernel(size_t type, const ir::Kernel& kernel) const;
    // The values of `layout`'s parent reads for the object in `row` of a pool of `type`,
    // at time `at`, in instruction order.
    void parentValues(size_t type, uint32_t row, const ColumnLayout& layout, double at, std::vector<Value>& out) const;
    // Fills the parent columns of a launch: for i in [begin, end) with mask[i] set, row
    // i of the table gets the parent values of the object in pool row
    // poolRows[i - poolRowsFirst] (poolRows null: row i), at time atRows[i] (null: `at`).
    void gatherParents(size_t type, const ColumnLayout& layout, std::span<const Buffer> table, const uint8_t* mask,
                       size_t begin, size_t end, double at, const double* atRows = nullptr,
                       const uint32_t* poolRows = nullptr, size_t poolRowsFirst = 0);
    // The parents of child pools whose parents' rows are in the memory, read back into
    // the host's handles (Pool::parent: hot reload).
    void parentsToHost();
    // The spawn kernels' ancestor reads (exports, `alive` and `age`) and own folds of
    // `type`'s sites in `sites`, for every row of its pool at `at`: columns of its spawn
    // tables, where a launch from records reads each emitter's at its row — the values
    // parentValues gives the host's launches (rt::eachEmitter; the GPU builds its blocks
    // from them). The pool's rows and its ancestors' are in the memory.
    void gatherSpawnParents(size_t type, std::span<const size_t> sites, double at);
    // A child type's whose rows are in the memory beside its parents': rows [begin, end)
    // of its ancestor columns (not folds) through `parents` from row `parentsFirst` on —
    // further up, through each ancestor pool's parent rows (Memory::ancestorRows) — where
    // they are (Memory::gatherThrough, gatherAlive, gatherAge: at `at`, or atRows' row
    // by row from `begin` — a batch's per-row clocks).
    void gatherThrough(size_t type, const ColumnLayout& layout, std::span<const Buffer> table, Buffer parents,
                       size_t parentsFirst, size_t begin, size_t end, double at, Buffer atRows = {});
    // The neighbour folds of a type's objects, for this step (rt/neighbours.cpp).
    void foldNeighbours(size_t type);
    void foldOnHost(const FoldLaunch& launch);
    FoldBuffers foldBuffers;
    // Rows [first, first + count) of a fold's launch columns (`p`, in `table`) set to a fold
    // over nothing: what an object created since the folds reads.
    void emptyFold(size_t type, const ColumnLayout::ParentColumn& p, std::span<const Buffer> table, size_t first,
                   size_t count);
    // Pool rows of `type` as the rows its fold columns are gathered from (in place).
    void foldRowsOf(size_t type, std::span<uint32_t> rows) const;
    // Points `table` at a pool's columns, kill flags and the scratch columns of the rest.
    void bindPool(size_t type, const ColumnLayout& layout, Scratch& scratch, std::vector<Buffer>& table);
    // chunk(c, begin, end) for every chunk of rows [first, end) (Backend::chunkRows rows
    // each), on several threads where the backend allows; chunkCount: how many there are.
    size_t chunkCount(size_t rows) const;
    // fn(begin, end) over chunks of rows [first, end) of the host's bookkeeping (its own
    // arrays, not a backend's memory), on every thread: chunks write rows of their own, so
    // results do not depend on the split.
    void forRows(size_t first, size_t end, core::FunctionRef<void(size_t, size_t)> fn);
    // Memory::scatter of several columns by the same rows: to[rows[i]] = from[fromFirst + i]
    // for each (from, to), split by rows over every thread where the backend is concurrent.
    void scatter(std::span<const std::pair<Buffer, Buffer>> columns, size_t fromFirst, std::span<const uint32_t> rows);
    void forChunks(size_t first, size_t end, core::FunctionRef<void(size_t, size_t, size_t)> chunk);

    // A column's values on the host: to change (host) or to read (view).
    template <typename T>
    T* host(Buffer b) const {
        return hostData<T>(memory, b);
    }
    template <typename T>
    const T* view(Buffer b) const {
        return viewData<T>(memory, b);
    }
};

// The phases of a step of `state`'s module (rt/schedule.cpp).
Schedule stepSchedule(const State& state);

}  // namespace psys::rt::detail
