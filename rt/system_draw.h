// Internal to rt/: drawing. The render kernel runs over a pool's live rows into render
// columns and the rows drawn are marked (alive, visible, every value finite), counting the
// points not drawn for a NaN or an infinity. The columns are handed over as they are
// (DrawColumns); reading them back to the host is `points`.
//
// Where the host draws every step, the step draws as it goes (DrawnInStep): each chunk of
// an update is rendered right after it, while its rows are in cache, over the rows alive
// at the end of the step, and objects created after their type's update are rendered in
// their creation batch and scattered into the render columns. `draw` then hands over the
// columns with no pass of its own. The values are the same bits either way on the
// interpreter and in exact maths: the render kernel sees the same state, clock, uniforms
// and parents (a test compares the two). The JIT's fast maths may differ in a value's last
// bit (3 values of the campfire's in 50 frames), as the rows of a batch and of a pool go
// through loops of different shapes, which it may fuse or vectorize differently.
#pragma once

#include <atomic>
#include <vector>

#include "rt/system_state.h"

namespace psys::rt::detail {

struct DrawnCount {
    size_t drawn = 0;
    uint64_t nonFinite = 0;
    uint64_t ticket = 0;  // a late launch's (RowsLaunch::late): the counts are to be collected
};

// The render launch of `type` over `table` (bound for its render layout) at the end of the
// step ending at `now`, rows to be chosen; `mask` selects the rows to draw.
RowsLaunch renderLaunch(State& s, size_t type, std::span<const Buffer> table, Buffer mask, double now);
// Renders rows [begin, end) of `launch` and marks the rows drawn (the backend, or here);
// `mask` is the launch's mask on the host. `poolRows`: where the table is a creation
// batch, its rows' pool rows (for their parents).
DrawnCount renderRows(State& s, size_t type, const RowsLaunch& launch, const uint8_t* mask, size_t begin, size_t end,
                      const uint32_t* poolRows = nullptr, size_t poolRowsFirst = 0);

// Drawing a pool chunk by chunk as its update goes (DrawnInStep): each chunk after its
// update, over the rows alive at the end of the step (those updated and not killed, and
// those created earlier in the step); the counts go to the type's DrawnInStep at done().
class ChunkDrawing {
public:
    ChunkDrawing(State& s, size_t type, double now);
    // Rows [begin, end) just updated (`kill`: their kill flags, or null).
    void chunk(const uint8_t* updatable, const uint8_t* kill, size_t begin, size_t end);
    // No row is alive: every row's mark is cleared.
    void none();
    void done();

private:
    State& s_;
    size_t type_, rows_;
    RowsLaunch launch_;
    uint8_t* shown_;
    const uint8_t* alive_;
    std::atomic<uint64_t> drawn_ = 0, nonFinite_ = 0;
};

class Drawing {
public:
    explicit Drawing(State& state);
    // Everything drawn must be computed again (after a trigger, a reload, a new extern
    // value); `step`: what the step drew as it went stays valid.
    void invalidate(bool step = false);
    const DrawColumns& draw(size_t type);
    std::vector<RenderPoint> points(size_t type);
    // The counts of draws a device answered late (RowsLaunch::late), into their
    // DrawColumns and the stats: at the next draw of the type, points(), stats().
    void takeCounts(size_t type);
    void takeCounts();
    // Whether the host drew since the last step (the next step then draws as it goes).
    bool drewSinceStep() const { return drew_; }
    void stepping() { drew_ = false; }

private:
    struct Type {
        DrawColumns columns;
        bool stale = true;
        std::vector<uint64_t> tickets;  // its render launches' counts, still to be collected
    };
    void hand(size_t type, DrawColumns& out);
    State& s_;
    std::vector<Type> types_;
    bool drew_ = false;
};

}  // namespace psys::rt::detail
