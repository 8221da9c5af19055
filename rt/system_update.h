// Internal to rt/: updating the objects of a type over a step (rt/system_update.cpp).
#pragma once

#include "rt/system_create.h"
#include "rt/system_state.h"

namespace psys::rt::detail {

// The phases of a step over `type`'s pool for (t1 − dt, t1] (one sub-step of @step, the
// `last` ending the step): the update pass (update, the survivors' exports, the render as
// it goes), its kills, the survivors' rate emissions (queued for Creation). The update
// pass does what its phase says (rt/schedule.h: its kills listed, late in the last sub-step).
void runUpdate(State& state, const Phase& phase, double dt, double t1, bool last);
void runKills(State& state, size_t type, double dt, double t1);
void runEmissions(State& state, Creation& creation, size_t type, double dt, double t1);

}  // namespace psys::rt::detail
