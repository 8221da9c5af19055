// Internal to rt/: updating the objects of a type over a step (rt/system_update.cpp).
#pragma once

#include "rt/system_create.h"
#include "rt/system_state.h"

namespace psys::rt::detail {

// Advances every updatable object of `type` over (t1 − dt, t1], in sub-steps no longer
// than its @step: its next state, its exports, kills, and what it emits (queued).
void updateType(State& state, Creation& creation, size_t type, double dt, double t1);

}  // namespace psys::rt::detail
