// Internal to rt/: creating objects. Emissions queue objects (with their exact creation
// times and their arguments, computed by the emitter's spawn kernel); `drain` creates
// what is queued, in queue order (the runs of types that emit nothing grouped by type),
// a batch of one type at a time: init, exports at creation, bursts, the first partial
// update to the end of the step (in sub-steps under @step), exports, then kills and
// emissions object by object in queue order. Every
// object is created this way, one or many (docs/runtime.md, "Creation").
#pragma once

#include <span>
#include <vector>

#include "rt/emission.h"
#include "rt/system_state.h"

namespace psys::rt::detail {

// An object emitting children: its row in its pool (for its id, parent and bookkeeping)
// and where its spawn kernels read it (the pool's columns, or a creation batch's).
struct Emitter {
    size_t type = 0;
    uint32_t row = 0;
    std::span<const Buffer> columns;  // empty: the pool's
    uint32_t columnRow = 0;           // its row in `columns`
    double at = 0;                    // the time its spawn kernels are evaluated at
    bool first = false;               // it is being created
};

class Creation {
    struct Batch;  // (below: a batch of one type being created)

public:
    explicit Creation(State& state);
    ~Creation();

    // Queues `count` children of emit site `site`, `perEvent` at a time; the k-th event is
    // at firstTime + k·spacing (spacing 0: all at once). Beyond the target's free capacity
    // the rest are dropped and counted, without work per dropped child.
    void queueChildren(const Emitter& emitter, int site, uint64_t count, uint64_t perEvent, double firstTime,
                       double spacing);
    // What an emitter creates in an update of `dt` ending at t1 (ir::EmitSite::inUpdate).
    // Rate emitters: events fall where the accumulated rate crosses a whole number, so a
    // stream is smooth within a step and a rate of 0.25/s emits at 4 s, 8 s, …; none from
    // an object this update kills (`dying`). Bursts on an event (an edge, a death): their
    // count, at t1 — a dying object's too (its death is this update's event).
    void emitInUpdate(const Emitter& emitter, std::span<const float> rate, std::span<const float> count, double dt,
                      double t1, bool dying);
    // emitInUpdate in two halves. The first decides row `row`'s emission at each site of
    // `o` (out[site]; children 0 where it emits nothing), moving on the row's own rate
    // accumulators alone (accumulated[site], null where the site has none): rows decide
    // theirs on every thread. The second queues them, sites in order, and counts their
    // invalid and clamped values; queued in row order, they give emitInUpdate's ids.
    static void emissionsOf(const ir::Object& o, double* const* accumulated, uint32_t row, std::span<const float> rate,
                            std::span<const float> count, double dt, double t1, bool dying, RateEmission* out);
    void queueEmissions(const Emitter& emitter, std::span<const RateEmission> emissions);
    // `type`'s rate accumulators, a column a site (null where a site has none): emissionsOf's.
    void accumulators(size_t type, std::vector<double*>& out) const;
    // The emissions of `type`'s rows that the memory decides (TypeInfo::rowsInMemory,
    // Memory::emitAtRate): its pool's after an update (`table` its update table), or a
    // batch's just created (`batch`: its rows [first, first + n) of `table`, clocked from
    // their creation, `rows` their rows in the pool, a u32 list in the memory; its bursts
    // at creation among the sites, their counts init's). `sites`' site k is emit site
    // emitSite[k], its kind set. `uniforms`: where the update's clock is uniform, its
    // uniform values (ColumnLayout::sharedEmit); null: the rates and counts are in the
    // table's columns. What they create is queued as queueBursts and emitInUpdate queue it,
    // row by row, sites in order: the same ids and rows. Only the totals come back to the
    // host: a target's objects are one run, and each site's emitters' spawn launches one
    // launch, both from the records where the memory keeps them.
    void emitInMemory(size_t type, const std::vector<Buffer>& table, const Value* const* uniforms, RateSites sites,
                      std::span<const size_t> emitSite, const Batch* batch, Buffer rows, double t1);
    // A trigger's (or the start's) kernel, evaluated on the host: once for the counts,
    // then once per created object for its arguments, so each draws its own numbers.
    void emitFromKernel(const ir::Trigger& trigger, std::span<const Value> params, uint32_t objectId);
    // Creates everything queued (and what that queues), each advanced to t1.
    void drain(double t1);
    // Runs the spawn launches queued since the last call, together (Backend::runChildren):
    // before anything they read changes — the end of a type's emissions (each sub-step's),
    // a batch's creation, each but the last sub-step of a new emitter batch's first update.
    void runSpawns();

private:
    // A run of objects queued together — one emitter's children at one site in one step,
    // a trigger's at one site — held as the rule that gives each its values, not object
    // by object: object k (k < count) has its arguments at staging row `staging + k`, the
    // id `id + k`, and is created at time(k).
    struct Run {
        size_t type;
        size_t staging;
        size_t count;
        Handle parent;
        double firstTime, spacing;  // events `spacing` apart, the first at firstTime,
        uint64_t perEvent;          // this many objects each
        uint32_t id;
        double time(size_t k) const { return eventTime(firstTime, k, perEvent, spacing); }
        // Or the objects of one site as emitAtRate left them, where its memory keeps them
        // (Memory::identifyRecords): `records` records of `runs` from `record` on (their
        // ids are not a range: `id`, `firstTime` and `spacing` are not the run's).
        Buffer runs = {};
        size_t record = 0, records = 0;
        // Their emitters (a child type's parents, Memory::parentsFromRecords): `stride`
        // records a row of emitters; row j the pool row emitters[emittersFirst + j] where
        // given (a batch's rows), else emittersFirst + j (a window's rows: from its first).
        size_t stride = 1;
        Buffer emitters = {};
        size_t emittersFirst = 0;
    };
    // Per type: the arguments of queued objects, one f32 column per component of the
    // type's parameters (kept or not); an object's row is its place among the type's
    // queued objects.
    struct Staging {
        std::vector<Buffer> args;
        size_t used = 0;
    };

    size_t stage(size_t type, size_t count);  // staging rows for `count` new objects of `type`
    // The spawn launch for `count` children of `emitter` at `site`, their arguments at
    // staging rows from `base`, the first child's draw `firstChild`.
    // (Null where the site has no spawn kernel: its children take no arguments.)
    // (`fromRecords`: its parent reads are the columns', not the host's: gatherSpawnParents.)
    ChildrenLaunch* queueSpawn(const Emitter& emitter, int site, uint32_t firstChild, size_t count, size_t base,
                               bool fromRecords = false);
    // Queues `count` objects of `type` (a run, or one run an object where objects are not
    // created in batches).
    void enqueue(const Run& run);
    void createBatch(size_t type, size_t from, size_t to, double t1);
    // One window of rows of emitInMemory's operation (Memory::emissionWindow): its records
    // and its totals, read back (those of the windows so far: the last one's are the
    // operation's).
    struct Window {
        Buffer runs;
        size_t at = 0, rows = 0;  // its rows are the operation's [at, at + rows)
        std::vector<uint32_t> total;
        RecordLayout layout;  // where its records are
        uint32_t kept(size_t site) const { return total[kTotalsSites + kTotalsPerSite * site]; }
    };
    // What emitInMemory's operation asked for, queued from its windows' records.
    void queueFromRecords(size_t type, const RateSites& sites, std::span<const size_t> emitSite, const Batch* batch,
                          const std::vector<Window>& windows, Buffer rows, double t1);
    void queueSiteLaunches(size_t type, const RateSites& sites, std::span<const size_t> emitSite, const Batch* batch,
                           const Window& w, const Window* before, size_t group, size_t base, size_t its, Buffer rows,
                           double t1);
    // The runs queue_[from, to) (a generation) type by type, in the module's order.
    void groupByType(size_t from, size_t to);  // see rt/system_queue.cpp
    // createBatch for a type whose rows are in the memory (rt/system_create_rows.cpp).
    void createInMemory(size_t type, Batch& b, size_t n, double t1);
    // `columns`: what goes to the pool rows after it (an emitter's accumulators join them).
    void exportSurvivors(size_t type, Batch& b, size_t n, Buffer mask, const Clock& clock);
    void bindInMemory(size_t type, Batch& b, size_t n);
    Buffer identifyInMemory(Batch& b, size_t n, size_t kept);
    void burstTablesAtCreation(size_t type, Batch& b, size_t n);
    void countCappedSubSteps(size_t type, Batch& b, size_t n, double t1);
    void agesAtSubStep(size_t type, Batch& b, size_t n, Buffer rows, Buffer nows);
    Clock firstUpdateInMemory(size_t type, Batch& b, size_t n, size_t kept, Buffer rows, double t1, LateKills& late,
                              std::vector<std::pair<Buffer, Buffer>>& columns);
    // The batch's state and exports with the pool's columns they go to, onto `columns`.
    void valueColumns(size_t type, const Batch& b, std::vector<std::pair<Buffer, Buffer>>& columns) const;
    // A batch's emissions the memory decides (emitInMemory): its bursts at creation, its
    // first update's (`inUpdate`) of the rows `mask` selects — to t1 from each one's
    // creation, or over each one's sub-step (`now`, `length`: RateSites) — the rates'
    // accumulators starting at 0 where `fresh` (and joining `columns`, for the pool).
    struct BatchSites {
        bool atCreation = false, inUpdate = false, fresh = false;
        Buffer mask, now, length;
    };
    void emitFromBatch(size_t type, Batch& b, size_t n, Buffer rows, double t1, const BatchSites& which,
                       std::vector<std::pair<Buffer, Buffer>>& columns);
    void launchInMemory(size_t type, Batch& b, size_t n, const ir::Kernel& kernel, const ColumnLayout& layout,
                        std::vector<Buffer>& table, const Clock& clock, LateKills* late, Buffer mask = {});
    Buffer parentsOf(size_t type, Batch& b, size_t n, size_t kept);
    // The fold columns of a batch's table (its launches over rows [first, first + n)) set to
    // a fold over nothing: what an object created in the step reads.
    void emptyFolds(size_t type, const ColumnLayout& layout, const std::vector<Buffer>& table, size_t first, size_t n);
    void identify(size_t type, Batch& b, size_t n);
    void identityColumns(size_t type, const std::vector<Buffer>& table, std::vector<std::pair<Buffer, Buffer>>& out) const;
    void atCreation(size_t type, Batch& b, size_t n);
    // Counts the updates beyond the stability limit in `type`'s stats.
    // `late`: its kills taken at the end of the step, or later (LateKills), listed there.
    void runBatch(const RowsLaunch& launch, size_t first, size_t end, size_t type, LateKills* late = nullptr);
    void firstUpdate(size_t type, Batch& b, size_t n, size_t allocated, double t1);
    void drawBatch(size_t type, Batch& b, size_t n, double t1);
    // `clock`: one update to the step's end (dt each object's age), or a sub-step's
    // per-row clock (the batch's now and dt columns).
    void advance(size_t type, Batch& b, size_t n, size_t maskColumn, const Clock& clock, LateKills* late = nullptr);
    void queueBursts(size_t type, Batch& b, size_t r);
    void killOrEmit(size_t type, Batch& b, size_t r, double dt, double t1);
    // Which of a batch's tables bindBatch binds: one over the state being advanced; init's
    // (that state, and emit counts of its own: a burst's count at creation is read after
    // the first update wrote that site's count in update's); a burst's spawn table (the
    // state at creation).
    enum class Table { Advanced, Init, Bursts };
    void bindBatch(size_t type, Batch& b, const ColumnLayout& layout, Scratch& parents, std::vector<Buffer>& table,
                   Table which, size_t parentsFirst = 0);

    // A spawn launch waiting for runSpawns, with the parent values it reads.
    struct Spawn {
        ChildrenLaunch launch;
        std::vector<Value> parents;
    };

    State& s_;
    std::vector<Spawn> spawns_;  // the first spawnsUsed_ queued: the rest kept for their vectors
    size_t spawnsUsed_ = 0;
    std::vector<ChildrenLaunch> launches_;  // runSpawns' list
    std::vector<Run> queue_;
    std::vector<Run> grouped_;         // groupByType's
    std::vector<size_t> groupStart_;   // groupByType's
    std::vector<size_t> queued_;   // per type: objects waiting in the queue
    std::vector<size_t> pending_;  // per type: rows a batch allocated for objects not yet created in order
    std::vector<Staging> staging_;
    std::vector<Batch> batches_;
    std::vector<Value> yields_;
    std::vector<float> rate_, count_;
    std::vector<double*> accumulated_;       // emitInUpdate's
    std::vector<RateEmission> rowEmissions_;  // emitInUpdate's
    Scratch emissions_;  // emitInMemory's: a new batch's accumulators by site,
    Scratch runs_;       // and the runs of each call in a drain (runsUsed_ of them so far)
    size_t runsUsed_ = 0;
};

// Per type: the scratch columns a batch is created in, indexed like the staging rows (so
// the staging columns are the batch's parameters as they are).
struct Creation::Batch {
    explicit Batch(Memory& m)
        : columns(m), initParents(m), updateParents(m), exportsParents(m), renderParents(m), burstParents(m),
          subStepAges(m) {}
    // (burstParents: each burst site's parent values its own, where the memory decides the
    // bursts — their spawn launches read them from the columns after the operation.)
    Scratch columns, initParents, updateParents, exportsParents, renderParents, burstParents;
    // A new emitter's sub-steps whose spawn arguments read an ancestor's age: per site, the
    // site's spawn table with those ages as of each object's own sub-step end
    // (Creation::agesAtSubStep; empty: the pool's table), and the columns they are in —
    // each sub-step's launches run before the next.
    Scratch subStepAges;
    std::vector<std::vector<Buffer>> agedTables;
    bool inUpdateAged = false;  // the sub-step now emitting reads agedTables
    ColumnLayout initLayout;
    std::vector<Buffer> initTable, updateTable, exportsTable, renderTable;
    std::vector<std::vector<Buffer>> burstTables;  // per emit site: the state at creation, for bursts
    std::vector<Run> runs;             // its runs (Creation::Run)
    std::vector<size_t> runFirst;      // per run: its first object's place in the batch
    size_t first = 0;                  // the batch's first staging row
    std::vector<uint32_t> poolRows;    // per object of the batch: its pool row, or kSkipRow (dropped)
    std::vector<uint32_t> subSteps;    // per object: the sub-steps of its first update
    std::vector<double> spans;         // per object: the length of its first update
    // Kept from batch to batch for their vectors: the columns scattered to the pool, and
    // the rows its first update killed with their times.
    std::vector<std::pair<Buffer, Buffer>> scattered;
    std::vector<uint32_t> killRows;
    std::vector<double> killAt;
};

// Scratch column indices of a batch.
constexpr size_t kCreated = 0, kIds = 1, kKill = 2, kNow = 3, kDt = 4, kMask = 5, kStepMask = 6, kExportMask = 7,
                 kZero = 8, kRenderMask = 9, kParents = 10, kLength = 11, kFirstValue = 12;

}  // namespace psys::rt::detail
