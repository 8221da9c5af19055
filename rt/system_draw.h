// Internal to rt/: drawing. The render kernel runs over a pool's live rows into render
// columns; a pass then marks the rows drawn (alive, visible, every value finite) and
// counts the points not drawn for a NaN or an infinity. The columns are handed over as
// they are (DrawColumns); reading them back to the host is `points`.
#pragma once

#include <vector>

#include "rt/system_state.h"

namespace psys::rt::detail {

class Drawing {
public:
    explicit Drawing(State& state);
    // Everything drawn must be computed again (after a step or a trigger).
    void invalidate();
    const DrawColumns& draw(size_t type);
    std::vector<RenderPoint> points(size_t type);

private:
    struct Type {
        explicit Type(Memory& m) : scratch(m) {}
        Scratch scratch;
        std::vector<Buffer> table;
        DrawColumns columns;
        bool stale = true;
    };
    State& s_;
    std::vector<Type> types_;
};

}  // namespace psys::rt::detail
