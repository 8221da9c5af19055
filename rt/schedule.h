// A step as data: the phases System::step runs, in order — per object type, parents
// before children — each naming the type it works on, what it reads and decides, and how
// an executor runs it (chunks of rows, or pieces of the host's bookkeeping, on every
// thread; or the memory's operations, where the rows are in the memory).
// The run-time builds it once per System from what each type's kernels yield (a type
// that never dies has no kills phase, one that emits nothing no emissions), and
// System::step walks it; `psysc run --print-schedule` prints it (docs/architecture.md,
// "The life of a step").
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace psys::rt {

enum class PhaseKind : unsigned char {
    Settle,     // what the last step still owes (a device's late kills) taken, its dead freed
    Ready,      // the rows created during the last step become updatable
    Neighbours, // the type's neighbour folds, over every object as the last step left them
    SubSteps,   // the next `span` phases, once per sub-step of @step(stepLimit)
    Update,     // the update kernel over the pool; in the same chunk the survivors' exports, and the render when the host draws every step
    Kills,      // the rows the update killed, frozen in row order (or, `late`, at the step's end)
    Emissions,  // rate emissions of the survivors, in row order: events, their times, ids, the queue
    Create,     // what is queued, in queue order: rows, init, bursts, the first update and what it kills and emits, until the queue is empty
    Release,    // late kills taken in their place; the dead nobody reads freed, their rows on the free stack
};

// How an executor runs a phase.
enum class Parallelism : unsigned char {
    Chunks,   // chunks of rows on every thread the backend allows, independent of their number
    // The host's bookkeeping in pieces of rows (detail::kHostRows) on every thread: what goes
    // in order (ids, the free stack, the deaths, the queue) goes at the places each piece's
    // count gives, or, for the few rows that emit, queued in row order after the pieces.
    Pieces,
    Memory,   // the memory's operations over every row (a device's threads; the host's memory's in
              // order), only totals to the host
    Host,     // on the host, a few values (no rows)
};

struct Phase {
    PhaseKind kind = PhaseKind::Settle;
    int type = -1;              // the object type it works on, or -1
    size_t span = 0;            // SubSteps: how many of the phases after it repeat
    double stepLimit = 0;       // SubSteps: @step(h)
    // Update, Kills: listed by the update's chunks, taken at the step's end (LateKills); in
    // a sub-step group, in its last sub-step only (an earlier one's kills are taken at once:
    // the next sub-step must not update the dead). The runner reads this, not the type.
    bool late = false;
    bool listed = false;        // Kills: the update's chunks listed the killed rows (no scan of flags)
    bool exports = false;       // Update: the survivors' exports in the same chunk
    bool render = false;        // Update: the render in the same chunk, when the host draws every step
    bool inMemory = false;      // Update, Kills, Emissions: the type's rows are in the memory (Pool::keepRowsInMemory)
    std::vector<int> targets;   // Emissions, Create: the types created
    bool events = false;        // Emissions: bursts on edges and deaths too (ir::EmitSite::whenKilled)
    Parallelism parallelism = Parallelism::Host;
};

struct Schedule {
    std::vector<std::string> types;  // the object types' names, by index
    std::vector<bool> inMemory;      // by index: the type's rows are in the memory
    std::vector<Phase> phases;
};

// The schedule as text: one line a phase, numbered, sub-steps indented.
std::string printSchedule(const Schedule& schedule);
const char* phaseName(PhaseKind kind);

}  // namespace psys::rt
