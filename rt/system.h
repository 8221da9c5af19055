// The run-time every backend shares: a compiled system, stepped through time.
//
// The host API in the LambdaCube spirit: build a System from a compiled module and a
// backend, set externs, fire triggers, step(dt), read the render values and the stats.
// What it guarantees (docs/runtime.md):
//   - parents are updated before children, so a child reads its parent's values of the
//     same step; a killed parent that children still read stays readable, frozen, with
//     `alive` false, and is freed after its last reader;
//   - objects created during a step get their exact creation time (rates below one per
//     second emit on time) and are advanced by the rest of the step at once;
//   - global time is a double and ages are float(now − created), exact for long runs;
//   - a pool never grows past its capacity: spawns beyond it are dropped and counted;
//   - bad input from the host (a NaN or negative dt, an unknown extern, NaN in an
//     extern, a NaN or negative emission rate) is an error value or a counted event,
//     never undefined behaviour.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <tbb/task_arena.h>

#include "ir/ir.h"
#include "rt/backend.h"
#include "rt/pool.h"

namespace psys::rt {

struct SystemOptions {
    uint32_t seed = 1;
    size_t capacity = 1 << 20;  // per object type, unless its @capacity says otherwise
    // Threads for the pool updates: 0 for every core. Results do not depend on it.
    unsigned threads = 0;
    // Create objects of simple types in batches (System::createBatch); false creates every
    // object one by one. Results are the same; tests compare the two.
    bool createInBatches = true;
};

struct TypeStats {
    std::string name;
    size_t live = 0;
    size_t frozen = 0;
    uint64_t created = 0;
    uint64_t killed = 0;
    uint64_t dropped = 0;  // spawns refused at capacity
};

struct Stats {
    std::vector<TypeStats> types;
    uint64_t steps = 0;
    uint64_t rejectedSteps = 0;        // NaN, infinite or negative dt
    uint64_t nonFiniteExterns = 0;     // NaN or infinite values set on an extern
    uint64_t invalidEmissions = 0;     // NaN or negative rates and counts (taken as 0)
    uint64_t nonFiniteRender = 0;      // points not drawn because a value was NaN or infinite
    uint64_t uniformEvaluations = 0;   // runs of uniform kernels (once per step per type, mostly)
    // Where the steps' time went: the update loops over pools, kills and emissions (with
    // the emitters' spawn kernels), creating objects (init and their first update).
    double loopSeconds = 0, emitSeconds = 0, createSeconds = 0;
};

struct RenderPoint {
    uint32_t id;
    std::array<float, 3> position;
    std::array<float, 4> color;
    float size;
};

class System {
public:
    System(ir::Module module, Backend& backend, SystemOptions options = {});
    ~System();
    System(const System&) = delete;
    System& operator=(const System&) = delete;

    // Host API. Errors come back as a message; nothing is changed then.
    std::optional<std::string> setExtern(std::string_view name, std::span<const float> value);
    // The same by handle, for hosts that set an extern every frame: -1 for an unknown name.
    int externHandle(std::string_view name) const { return module_.externIndex(std::string(name)); }
    std::optional<std::string> setExtern(int handle, std::span<const float> value);
    std::optional<std::string> fire(std::string_view trigger, std::span<const float> args);
    std::optional<std::string> step(double dt);
    // Threads for the pool updates from now on: 0 for every core. Results do not change.
    void setThreads(unsigned threads);

    double time() const { return now_; }
    uint64_t stepCount() const { return step_; }
    const ir::Module& module() const { return module_; }
    const Pool& pool(size_t type) const { return pools_[type]; }
    size_t typeCount() const { return pools_.size(); }
    int typeIndex(std::string_view name) const;

    // What is drawn for each type after the latest step (or trigger): visible objects only.
    const std::vector<RenderPoint>& render(size_t type);
    Stats stats() const;

private:
    struct Creation {
        size_t type;
        size_t args;  // the first of its arguments in queueArgs_, one per parameter of the type
        Handle parent;
        double time;
        uint32_t id;
    };

    KernelInputs inputs(size_t type, uint32_t row, double at, float dt, bool first, std::vector<Value>& params,
                        std::vector<Value>& state);
    void runKernel(size_t type, uint32_t row, const ir::Kernel& kernel, KernelInputs in);
    const Value* uniforms(size_t type, const ir::Kernel& kernel, const KernelInputs& in);
    std::pair<int, uint32_t> ancestor(size_t type, uint32_t row, int depth) const;
    void updatePool(size_t type, double dt, double t1);
    void bindColumns(size_t type, const BatchLayout& layout, std::vector<std::vector<float>>& scratch,
                     std::vector<void*>& table);
    void gatherParents(size_t type, const BatchLayout& layout, void* const* table, const uint8_t* mask,
                       size_t begin, size_t end, double at) const;
    void emitAtRate(size_t type, uint32_t row, std::span<const float> rate, std::span<const float> count, double dt,
                    double t1);
    void update(size_t type, uint32_t row, double dt, double t1);
    void forChunks(size_t rows, const std::function<void(size_t)>& chunk);
    RowBatch stepBatch(size_t type, const ir::Kernel& kernel, const uint8_t* mask, const std::vector<void*>& columns,
                       double time, double dt);
    void updateOnce(size_t type, uint32_t row, double dt, double t1);
    void create(const Creation& c, double t1);
    void queueChildren(size_t type, uint32_t row, int site, uint64_t count, uint64_t perEvent, double firstTime,
                       double spacing, double evalTime, bool first);
    void drain(double t1);
    void createBatch(size_t type, size_t from, size_t to, double t1);
    void kill(size_t type, uint32_t row);
    void releaseReader(size_t type, Handle parent);
    void emitFromKernel(const ir::Trigger& trigger, std::span<const Value> params, uint32_t objectId);
    void start();
    Backend::Plan plan() const;

    ir::Module module_;
    Backend& backend_;
    SystemOptions options_;
    std::vector<Pool> pools_;
    std::vector<int> parentType_;  // per type: the type of its parent, or -1
    std::vector<double> stepLimit_;  // per type: the longest update (@step), or 0
    std::vector<Value> externs_;
    std::vector<std::vector<RenderPoint>> render_;
    std::vector<bool> renderStale_;
    std::vector<Creation> queue_;
    std::vector<Value> queueArgs_;
    std::vector<size_t> queued_;  // per type: creations waiting in the queue
    std::vector<size_t> pending_;  // per type: rows a batch allocated for objects not yet created in order
    std::vector<std::pair<size_t, uint32_t>> dying_;
    std::vector<TypeStats> typeStats_;
    Stats stats_;
    double now_ = 0;
    double lastDt_ = 0;
    uint64_t step_ = 0;
    uint32_t nextId_ = 0;
    bool started_ = false;
    std::vector<Value> yields_;
    // Scratch for the object-by-object paths (creation, sub-steps, triggers), reused so
    // that creating an object allocates nothing.
    std::vector<Value> params_, state_, createArgs_;
    std::vector<float> rate_, count_;
    std::vector<double> bursts_;
    // Per type and served kernel: the uniform values and the (dt, time, externs) they
    // were computed for.
    struct UniformCache {
        bool valid = false;
        float dt = 0, time = 0;
        uint64_t externs = 0;
        std::vector<Value> values;
    };
    std::vector<std::array<UniformCache, 3>> uniformCache_;
    uint64_t externsVersion_ = 0;
    // Per type: the batched update and exports kernels' layouts and scratch columns.
    struct PoolBatch {
        BatchLayout update, exports, render;
        std::vector<bool> drawn;  // per render yield kind (visible, position, colour, size): whether it is yielded
        bool kills = false, rateEmits = false;
        std::vector<bool> counted, rated;  // per emit site: whether the update yields its count, its rate
        std::vector<uint8_t> kill, exportMask, aliveMask;
        std::vector<std::vector<uint32_t>> killed;  // per chunk: the rows that died, in order
        std::vector<std::vector<float>> updateScratch, exportScratch, renderScratch;
        std::vector<void*> updateColumns, exportColumns, renderColumns;
        // Creation in batches (createBatch): for types without sub-steps, exports, bursts
        // or a parent; the others are created one by one.
        bool createInBatches = false;
        std::vector<uint32_t> newRows;
        std::vector<size_t> newQueueIndex;
        std::vector<double> newCreated;
        std::vector<uint32_t> newIds;
        std::vector<uint8_t> newKill, newMask;
        std::vector<std::vector<float>> newColumns;  // one per column position of the layout
        std::vector<void*> newTable;
    };
    std::vector<PoolBatch> batches_;
    std::unique_ptr<tbb::task_arena> arena_;
};

}  // namespace psys::rt
