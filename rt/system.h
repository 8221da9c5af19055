// The run-time every backend shares: a compiled system, stepped through time.
//
// The host API in the LambdaCube spirit: build a System from a compiled module and a
// backend, set externs, fire triggers, step(dt), draw, read the stats. What it guarantees
// (docs/runtime.md):
//   - parents are updated before children, so a child reads its parent's values of the
//     same step; a killed parent that children still read stays readable, frozen, with
//     `alive` false, and is freed after its last reader;
//   - objects created during a step get their exact creation time (rates below one per
//     second emit on time) and are advanced by the rest of the step at once;
//   - global time is a double and ages are float(now − created), exact for long runs;
//   - a pool never grows past its capacity: spawns beyond it are dropped and counted;
//   - bad input from the host (a NaN or negative dt, an unknown extern, NaN in an
//     extern, a NaN or negative emission rate) is an error value or a counted event,
//     never undefined behaviour;
//   - results do not depend on the number of threads.
// How a step is carried out is docs/architecture.md ("The life of a step"); the parts
// are rt/system_*.cpp.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "ir/ir.h"
#include "rt/backend.h"
#include "rt/pool.h"
#include "rt/schedule.h"

namespace psys::rt {

class System;

struct SystemOptions {
    uint32_t seed = 1;
    size_t capacity = 1 << 20;  // per object type, unless its @capacity says otherwise
    // Threads for launches over pools: 0 for every core. Results do not depend on it.
    unsigned threads = 0;
    static constexpr unsigned kMostThreads = 256;  // TBB's own limit: the most `threads` asks for
    // Create the objects queued in a step in batches of any size; false: one at a time.
    // Results are the same (tests compare the two).
    bool createInBatches = true;
    // When the host draws every step, compute what is drawn during the step, chunk by
    // chunk as the update leaves it in cache (rt/system_draw.h); false: in draw() alone.
    // Results are the same (tests compare the two).
    bool drawInStep = true;
    // Take the kills of objects whose dead nobody looks at during the step at its end
    // (rt/system_state.h, LateKills), so a device need not wait for them mid-step;
    // false: at once. Results are the same, rows included (tests compare the two).
    bool lateKills = true;
    // Where the pools of objects that only die (late kills, nothing reads them, no bursts
    // or sub-steps) or never die keep their rows — the free stack, generations, masks: in
    // the memory (Pool::keepRowsInMemory, its operations doing the bookkeeping where the
    // columns are) where the backend asks for it (Backend::keepsRowsInMemory: a device),
    // always, or never. Wherever they are kept there, so are the rows of emitters whose
    // emissions the memory can decide — at a rate, in bursts at creation, on edges, on
    // deaths (Memory::emitAtRate: rt/system_state.cpp, TypeInfo::rowsInMemory).
    // Results are the same, rows included (tests compare them).
    enum class Rows : uint8_t { AsBackend, InMemory, OnHost } rows = Rows::AsBackend;
    // Where the system's particle memory comes from (rt/host_allocator.h): unset, the
    // library's own. It outlives the system.
    HostAllocator allocator;
    // Called at the end of the step after which the system is finished (System::finished),
    // once each time it becomes so: a host may recycle the system there.
    std::function<void(const System&)> onFinished;
};

// An instance of an instanced program (docs/embedding.md, "Instances"): its slot in the
// low 32 bits, the slot's generation in the high ones. 0 is the system's own.
using InstanceHandle = uint64_t;
enum class InstanceLife : uint8_t {
    Playing,   // its `spawn`s ran; it emits
    Stopped,   // its emitters emit no more at a rate; what it made lives out its life
    Killed,    // its objects die at the next step, creating nothing
    Finished,  // nothing of it is left (or it never was)
};

struct TypeStats {
    std::string name;
    size_t live = 0;
    size_t frozen = 0;
    uint64_t created = 0;
    uint64_t killed = 0;
    uint64_t dropped = 0;  // spawns refused at capacity (stops at 2^64 - 1 rather than wrapping)
    // Object updates whose step was beyond the stability limit of the type's integration
    // method for a decay rate in its equations (k·dt > 2 for Euler): such an integral
    // oscillates and grows. @step, or @integrator(exponential), fixes it.
    uint64_t unstable = 0;
    // Updates whose @step sub-steps were capped at 10,000 (so each was longer than @step):
    // `@step(1e-30)`, or a step of 1e30 s.
    uint64_t cappedSubSteps = 0;
};

struct Stats {
    std::vector<TypeStats> types;
    uint64_t steps = 0;
    uint64_t rejectedSteps = 0;        // NaN, infinite or negative dt
    uint64_t nonFiniteExterns = 0;     // NaN or infinite values set on an extern (refused)
    uint64_t outOfRangeExterns = 0;    // values outside an extern's declared range (refused)
    uint64_t invalidEmissions = 0;     // NaN or negative rates and counts (taken as 0)
    uint64_t clampedEmissions = 0;     // counts and rates asking for more than 1e18 objects (taken as 1e18)
    uint64_t nonFiniteRender = 0;      // points not drawn because a value was NaN or infinite
    uint64_t uniformEvaluations = 0;   // runs of uniform kernels (once per step per type, mostly)
    uint64_t folds = 0;                // neighbour groups folded (once per step per group)
    // Where the time went: the update loops over pools, kills and emissions (with the
    // emitters' spawn kernels), creating objects (init and their first update), drawing,
    // the neighbour folds.
    double loopSeconds = 0, emitSeconds = 0, createSeconds = 0, drawSeconds = 0, foldSeconds = 0;
};

// One drawn point, read back (System::points).
struct RenderPoint {
    uint32_t id;
    std::array<float, 3> position;
    std::array<float, 4> color;
    float size;
    float rotation = 0, frame = 0;       // a sprite's (0 for the others)
    std::array<float, 3> end{};          // a streak's other end (0 for the others)
    std::vector<std::array<float, 3>> trail;  // a trail's points behind its head, nearest first
};

// What is drawn for one type after the latest step, as columns in the backend's memory:
// row r is drawn when visible[r] is 1 (alive, its point visible, every value finite).
// A viewer draws straight from these; `System::points` reads them back.
struct DrawColumns {
    size_t rows = 0;
    size_t drawn = 0;       // rows with visible = 1, where `counted`
    // False where a device computed what is drawn and the host did not wait for its count:
    // `drawn` is then not known yet (the columns are); System::stats and points take it.
    bool counted = true;
    Buffer visible;         // f32, 0 or 1
    Buffer position[3];     // f32
    Buffer color[4];        // f32
    Buffer size;            // f32
    Buffer rotation, frame; // f32: a sprite's
    Buffer end[3];          // f32: a streak's other end
    Buffer ids;             // u32
    Buffer instance;        // f32: each row's instance (an instanced program's slot; else none)
    // The drawn values in render-column order past `visible` (ColumnLayout::kPosition …):
    // position x y z, colour r g b a, size, rotation, frame, end x y z.
    static constexpr int kValues = 13;
    std::array<Buffer, kValues> values() const {
        return {position[0], position[1], position[2], color[0], color[1], color[2], color[3],
                size,        rotation,    frame,       end[0],   end[1],   end[2]};
    }
    // A component every row draws alike has no column (an invalid buffer above) and its
    // value here, in that order (ColumnLayout::renderConstant).
    std::array<float, kValues> constant{};
    // A trail's points behind its head, nearest first, x y z each (point k + 1 back at
    // 3k … 3k + 2); a component every row draws alike has no column and its value in
    // trailConstant. Empty for the other commands.
    std::vector<Buffer> trail;
    std::vector<float> trailConstant;
    size_t trailPoints() const { return trail.size() / 3; }
};

// What hot reload kept and lost (rt/reload.cpp, docs/runtime.md).
struct ReloadReport {
    size_t carried = 0;                    // objects carried over
    size_t dropped = 0;                    // objects of types the new module does not have
    std::vector<std::string> droppedTypes; // those types
    std::vector<std::string> newSlots;     // "type.slot": state the new module adds (started from init)
    std::vector<std::string> lostSlots;    // "type.slot": state the new module no longer has (or with another type)
    std::vector<std::string> spawned;      // types the new `spawn`s name that the old ones did not: spawned
};

// Every launch shape a System of `module` uses: what its constructor hands
// Backend::prepare. A host may prepare a backend with it ahead of time, on another thread
// (the constructor then finds everything compiled).
Plan launchPlan(const ir::Module& module);

namespace detail {
struct State;
class Creation;
class Drawing;
}  // namespace detail

// An extern's type as the program spells it (`float`, `vec3`, `bool`, `color`): for messages.
std::string languageName(const ir::Extern& e);
// A value's type as the language spells it without more to go on.
std::string languageName(const ir::Type& t);
// A parameter's type as the program spells it (a trigger's `point`, `color`).
std::string languageName(const ir::Param& p);

class System {
public:
    System(ir::Module module, Backend& backend, SystemOptions options = {});
    ~System();
    System(const System&) = delete;
    System& operator=(const System&) = delete;

    // Host API. Errors come back as a message; nothing is changed then.
    std::optional<std::string> setExtern(std::string_view name, std::span<const float> value);
    // The same by handle, for hosts that set an extern every frame: -1 for an unknown name.
    int externHandle(std::string_view name) const;
    // (On an instanced program, every instance's value: each reads its own.)
    std::optional<std::string> setExtern(int handle, std::span<const float> value);
    // The current value of an extern (its default until set).
    std::optional<Value> externValue(std::string_view name) const;
    // (On an instanced program, on the system's own instance: played again if it finished.)
    std::optional<std::string> fire(std::string_view trigger, std::span<const float> args);
    // Whether fire(trigger, `values` numbers) would be accepted: nullopt, or why not.
    std::optional<std::string> checkFiring(std::string_view trigger, size_t values) const;
    // … and its values: finite numbers, as an extern's (a NaN would reach every object it creates).
    std::optional<std::string> checkFiring(std::string_view trigger, std::span<const float> args) const;
    // Whether every type's capacity (its @capacity, else the options') fits in this
    // machine's memory at the pool's bytes a row: nullopt, or an error that names the bytes.
    static std::optional<std::string> checkCapacity(const ir::Module& module, const SystemOptions& options);
    // Whether `backend` runs `module`: nullopt, or why not (the glsl backend does not play
    // instances yet). The constructor throws that.
    static std::optional<std::string> checkBackend(const ir::Module& module, Backend& backend);
    std::optional<std::string> step(double dt);
    // Runs `seconds` ahead at once in equal steps of at most `longest` (a warm-up: what a
    // host shows from its first frame has been running a while). Nothing is drawn in them
    // unless the host draws between (it does not: one call). Errors: a bad time.
    std::optional<std::string> prewarm(double seconds, double longest);
    // Back to the start — time 0, nothing created, the counters at 0 — with the same seed
    // (the same run again), the externs as the host last set them, and nothing compiled
    // again.
    void reset();
    // The latest time a step may reach: 2^32 s, where a double still counts microseconds.
    static constexpr double kLatestTime = 4294967296.0;
    // Room for `rows` objects of `type` made now (at most its capacity), so that steps with
    // that many need no more: each chunk's list of deaths with room for the whole chunk
    // (where its deaths are listed as they happen: 8 bytes a row more, in two sets that
    // take turns), and the pool's columns given their pages. Results do not change.
    std::optional<std::string> reserve(size_t type, size_t rows);
    // Threads for launches over pools from now on: 0 for every core. Results do not change.
    void setThreads(unsigned threads);

    // Instances (docs/embedding.md, "Instances"), for an instanced program — one that reads
    // `instance` (ir::Module::instanced); the others refuse them. Each plays the `spawn`s
    // again, its objects (and theirs) reading its transform as `instance.pos`, … . The
    // system's own instance, handle 0, plays when the system starts (kill it before the
    // first step for a system of the host's plays alone). `transform`: 16 floats, a 4×4
    // affine matrix in columns (OpenGL's, GLM's order; its last row 0 0 0 1), empty for the
    // identity. Starting one compiles nothing: its objects join the effect's pools.
    std::optional<std::string> play(std::span<const float> transform, InstanceHandle& out);
    std::optional<std::string> setTransform(InstanceHandle instance, std::span<const float> transform);
    std::optional<std::string> stop(InstanceHandle instance);  // no more emission at a rate
    std::optional<std::string> kill(InstanceHandle instance);  // its objects die at the next step
    // A trigger fired on one instance: what it creates belongs to it.
    std::optional<std::string> fire(std::string_view trigger, std::span<const float> args, InstanceHandle instance);
    // An extern's value for one instance (its objects, triggers and `spawn`s read it),
    // checked as setExtern checks it; until set, and once setExtern sets every instance's,
    // the effect's.
    std::optional<std::string> setInstanceExtern(InstanceHandle instance, int handle, std::span<const float> value);
    std::optional<Value> instanceExtern(InstanceHandle instance, int handle) const;
    // Its speed: seconds of its own a second of the system's (1 at play; 0 to 100), and
    // pause, which keeps the speed for its resumption: its ages, motion and emissions at
    // its own pace, in the effect's one update (rt/system_speeds.cpp). Read from the next
    // step on; the objects' rows must be the host's (not SystemOptions::Rows::InMemory).
    std::optional<std::string> setSpeed(InstanceHandle instance, double speed);
    std::optional<std::string> pause(InstanceHandle instance, bool paused);
    std::optional<float> speed(InstanceHandle instance) const;  // none for a handle of none
    std::optional<bool> paused(InstanceHandle instance) const;
    InstanceLife life(InstanceHandle instance) const;  // Finished also for a handle never given
    size_t instanceCount() const;                      // not finished, the system's own included
    // The instances that finished in the latest step, in slot order: a host learns of them
    // without asking each.
    std::span<const InstanceHandle> finishedInstances() const;

    // Events (`notify "hit"(pos, speed)`: docs/language.md, "Events"): the names the program
    // notifies, and one's notifications of the latest step (and of triggers fired since),
    // in row order, `width` floats each — its values' components in order, then, in an
    // instanced program, the instance's slot — into `out` (reused). Any backend (a device's
    // are read back).
    std::vector<std::string> eventNames() const;
    std::optional<std::string> events(std::string_view name, std::vector<float>& out, size_t& width);

    // Whether the system can produce nothing more of its own accord: it has started,
    // nothing is alive and nothing waits to be created. A trigger fired later still
    // creates objects (and the system is no longer finished). On a device whose kills come
    // late (RowsLaunch::late) it is known once they are counted, without waiting for them:
    // at worst a step after the last object died.
    bool finished() const;

    double time() const;
    uint64_t stepCount() const;
    const ir::Module& module() const;
    const SystemOptions& options() const;
    const Pool& pool(size_t type) const;
    size_t typeCount() const;
    int typeIndex(std::string_view name) const;
    Backend& backend() const;
    // The phases a step runs, in order (rt/schedule.h; psysc run --print-schedule).
    const Schedule& schedule() const;

    // What is drawn for `type` after the latest step (or trigger), computed on first ask.
    // On a device the host does not wait for it: its count comes later (DrawColumns::counted).
    const DrawColumns& draw(size_t type);
    // The box around what draw(type) draws (culling, a camera's fit): reduced where the
    // columns are, only 24 bytes to the host (Memory::bounds).
    Bounds bounds(size_t type);
    // The same read back to the host: the drawn points in row order (for dumps and tests).
    std::vector<RenderPoint> points(size_t type);
    // The counters (a device's render counts taken first: it may wait for the GPU). The
    // kills a device still owes from the last step (RowsLaunch::late) are counted once it
    // has them ready, without waiting: until then `killed` and `live` are a step behind.
    Stats stats() const;
    // The same into `out`, reusing its vectors: a host that reads them every frame allocates nothing.
    void stats(Stats& out) const;
    // Takes everything a device still owes — the last step's late kills, draws' counts —
    // waiting for it: the stats and pools are then exact (before a final report, a
    // comparison of rows).
    void finish();

    // Hot reload: this (new, not yet stepped) system takes over `old`'s objects, carried
    // over by type name: ids, creation times, parents, the state slots and parameters whose
    // name and type still match, and what it emits, continuing at `old`'s time, step and
    // externs. Unchanged source continues bit for bit. docs/runtime.md, "Hot reload".
    ReloadReport carryOver(const System& old);

private:
    void start();
    // The instance a handle names, or why it names none that may change.
    std::optional<std::string> liveInstance(InstanceHandle instance, uint32_t& slot) const;
    std::optional<std::string> checkSpeeds() const;  // why speeds cannot be set, if they cannot
    std::optional<std::string> fireOn(std::string_view trigger, std::span<const float> args, uint32_t slot);
    // An extern's value as the host gives it, checked (its width, a bool's 0 or 1, finite,
    // its range: counted in the stats where not): into `out`, or why not.
    std::optional<std::string> checkExtern(int handle, std::span<const float> value, Value& out);
    void runPhases(size_t first, size_t end, double dt, double t1, bool last, double stepEnd);
    void initNewSlots(const ReloadReport& report);

    std::unique_ptr<detail::State> state_;
    std::unique_ptr<detail::Creation> creation_;
    std::unique_ptr<detail::Drawing> drawing_;
};

}  // namespace psys::rt
