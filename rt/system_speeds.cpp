// Instance speeds and pause (docs/embedding.md, "Instances"): an instance played at speed
// v lives v seconds of its own in each second of the system's; paused, none.
//
// All instances share the pools and one update a step, at the system's time t1. A row
// of a scaled instance gets, in that update, its own dt — v · dt — and its creation time
// moves on by (1 − v) · dt first, so that its age at t1 (t1 − created) has grown by
// v · dt: what ages, integrators, kills and draws read is the instance's own time, with
// no per-row clock to keep. Its window in the step is then (t1 − v · dt, t1] in the same
// terms: where its emissions fall (the rate rule over v · dt) and the time of its
// deaths (t1 − v · dt, what its children read as its age). What it creates in the step
// is created in that window, and its first update (to t1, as any new object's) is the
// rest of it. `time` in equations stays the system's.
//
// Paused is a speed of 0: the update runs with dt 0 — nothing moves, nothing ages or is
// emitted, nothing dies of age; what counts updates rather than time (`prev`, a value
// drawn afresh each update) still counts them.
//
// A step where every instance runs at speed 1 is the step it always was (uniform clock):
// the speeds cost nothing until one is set.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/instances.h"
#include "rt/system.h"
#include "rt/system_state.h"

namespace psys::rt {
namespace detail {

void State::takeSpeeds() {
    scaledStep = false;
    fastest = 0;
    stepSpeeds.resize(instances.size());
    for (size_t slot = 0; slot < instances.size(); ++slot) {
        const InstanceSlot& i = instances[slot];
        const bool lives = i.life != InstanceLife::Finished;
        stepSpeeds[slot] = !lives ? 1.0f : i.paused ? 0.0f : i.speed;
        if (!lives) continue;
        scaledStep = scaledStep || stepSpeeds[slot] != 1.0f;
        // (A killed one's objects die in this step: their sub-steps need not count.)
        if (i.life != InstanceLife::Killed) fastest = std::max(fastest, stepSpeeds[slot]);
    }
    if (!scaledStep) fastest = 1;
}

State::RowSpeeds State::rowSpeeds(size_t type) const {
    const Pool& pool = pools[type];
    if (stepSpeeds.empty() || pool.paramColumn.empty() || pool.paramColumn.back() < 0) return {};
    return {view<float>(pool.params.column(static_cast<size_t>(pool.paramColumn.back()), 0)), stepSpeeds.data(),
            static_cast<uint32_t>(stepSpeeds.size())};
}

float State::RowSpeeds::operator()(uint32_t row) const {
    // (The clamp every backend applies to the `instance` op: core::instanceSlot.)
    return instance ? speeds[core::instanceSlot(instance[row], slots, 0, 1) - 1] : 1.0f;
}

void State::scaleRows(size_t type, double dt, float* dts, const uint8_t* updatable, size_t begin, size_t end) {
    double* created = host<double>(pools[type].created);
    const RowSpeeds speedOf = rowSpeeds(type);
    for (size_t r = begin; r < end; ++r) {
        if (!updatable[r]) continue;
        const double v = speedOf(static_cast<uint32_t>(r));
        dts[r] = static_cast<float>(v * dt);
        created[r] += (1.0 - v) * dt;
    }
}

}  // namespace detail

namespace {

// The fastest speed an instance may run at. An update of v · dt takes v times the
// sub-steps of one at the system's speed, and each step moves the creation times of a
// fast instance's objects back by (v − 1) · dt: past 100, a longer step says the same.
constexpr double kMaxSpeed = 100;

}  // namespace

std::optional<std::string> System::checkSpeeds() const {
    for (size_t t = 0; t < state_->types.size(); ++t)
        if (state_->types[t].rowsInMemory)
            return fmt::format("instance speeds and pause need the objects' rows on the host, and `{}`'s are in the "
                               "backend's memory (SystemOptions::rows)",
                               state_->pools[t].object().name);
    return std::nullopt;
}

std::optional<std::string> System::setSpeed(InstanceHandle instance, double speed) {
    uint32_t slot = 0;
    if (auto error = liveInstance(instance, slot)) return error;
    if (!std::isfinite(speed) || speed < 0 || speed > kMaxSpeed)
        return fmt::format("an instance's speed is a number of seconds of its own a second, from 0 to {}, not {}",
                           kMaxSpeed, speed);
    if (speed != 1)
        if (auto error = checkSpeeds()) return error;
    state_->instances[slot].speed = static_cast<float>(speed) + 0.0f;  // (-0 is 0)
    return std::nullopt;
}

std::optional<std::string> System::pause(InstanceHandle instance, bool paused) {
    uint32_t slot = 0;
    if (auto error = liveInstance(instance, slot)) return error;
    if (paused)
        if (auto error = checkSpeeds()) return error;
    state_->instances[slot].paused = paused;
    return std::nullopt;
}

std::optional<float> System::speed(InstanceHandle instance) const {
    uint32_t slot = 0;
    if (liveInstance(instance, slot)) return std::nullopt;
    return state_->instances[slot].speed;
}

std::optional<bool> System::paused(InstanceHandle instance) const {
    uint32_t slot = 0;
    if (liveInstance(instance, slot)) return std::nullopt;
    return state_->instances[slot].paused;
}

}  // namespace psys::rt
