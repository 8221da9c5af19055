// Instances (core/instances.h, docs/embedding.md "Instances"): an instanced program's
// `spawn`s played once per instance, all of them in the effect's pools and one update.
// The run-time keeps the table the kernels read — each slot's transform and flags — and
// each slot's life; an instance finishes after the step that leaves none of its objects.
#include <algorithm>
#include <cmath>
#include <cstddef>

#include <fmt/format.h>

#include "core/few.h"
#include "rt/rng.h"
#include "rt/system.h"
#include "rt/system_create.h"
#include "rt/system_draw.h"
#include "rt/system_support.h"

namespace psys::rt {
namespace {

using Wait = detail::Ledger::Wait;

uint32_t slotOf(InstanceHandle h) { return static_cast<uint32_t>(h & 0xffffffffu); }
uint32_t generationOf(InstanceHandle h) { return static_cast<uint32_t>(h >> 32); }
InstanceHandle handle(uint32_t slot, uint32_t generation) { return static_cast<InstanceHandle>(generation) << 32 | slot; }

// A transform as the host gives it: 16 finite floats in columns, affine.
std::optional<std::string> checkTransform(std::span<const float> m) {
    if (m.empty()) return std::nullopt;
    if (m.size() != 16)
        return fmt::format("an instance's transform is a 4×4 matrix: 16 numbers in columns, not {}", m.size());
    for (float x : m)
        if (!std::isfinite(x)) return fmt::format("an instance's transform takes finite numbers, not {}", x);
    if (m[3] != 0 || m[7] != 0 || m[11] != 0 || m[15] != 1)
        return fmt::format("an instance's transform is affine: its last row is 0 0 0 1, not {} {} {} {} (the "
                           "matrix in columns, as OpenGL and GLM keep it)",
                           m[3], m[7], m[11], m[15]);
    return std::nullopt;
}

// Writes the transform (the identity where empty) into a slot's records, flags kept.
void writeTransform(Value* records, std::span<const float> m) {
    for (int column = 0; column < 4; ++column)
        for (int row = 0; row < 3; ++row)
            records[column].f[static_cast<size_t>(row)] =
                m.empty() ? (row == column ? 1.0f : 0.0f) : m[static_cast<size_t>(4 * column + row)];
}

}  // namespace

namespace detail {

void State::growInstances(size_t slots) {
    const size_t before = instances.size();
    if (slots <= before) return;
    instances.resize(slots);
    externs.resize(module.externs.size() + 1 + instanceValues() * slots);
    externs[module.externs.size()].f[0] = static_cast<float>(slots);
    for (size_t slot = before; slot < slots; ++slot) {
        Value* records = instanceRecord(slot);
        writeTransform(records, {});
        std::copy(externs.begin(), externs.begin() + static_cast<std::ptrdiff_t>(module.externs.size()),
                  records + core::kInstanceOwnValues);
        records[core::kInstanceIndex].f[3] = static_cast<float>(slot);
        records[core::kInstancePosition].f[3] = 1;
        setLife(slot, InstanceLife::Finished);
    }
}

void State::setLife(size_t slot, InstanceLife life) {
    instances[slot].life = life;
    Value* records = instanceRecord(slot);
    records[core::kInstanceEmitting].f[3] = life == InstanceLife::Playing ? 1.0f : 0.0f;
    records[core::kInstanceKilled].f[3] = life == InstanceLife::Killed || life == InstanceLife::Finished ? 1.0f : 0.0f;
    ++externsVersion;
}

// Marks the slots that still have a live object in the pools' hidden `instance` columns;
// a slot playing, stopped or killed with none finishes. The scan stops once every slot
// that may finish is marked — in a steady state after a few rows a slot, not the pools'
// every row; it reads them all only in a step where some instance has none left. Only
// where the host addresses the pools (the CPU's memory: the glsl backend refuses
// instanced programs).
void State::finishInstances() {
    finishedInstances.clear();
    if (!module.instanced() || !memory.hostResident()) return;
    ledger.settle(Wait::No);  // what is ready: else a step late
    const auto slots = static_cast<uint32_t>(instances.size());
    instanceLive.assign(slots, 0);
    uint32_t* seen = instanceLive.data();
    size_t unseen = 0;
    for (uint32_t slot = 0; slot < slots; ++slot) {
        if (instances[slot].life == InstanceLife::Finished) seen[slot] = 1;
        else ++unseen;
    }
    const float last = static_cast<float>(slots - 1);
    // The smallest pools first: an effect's emitters are few, one or so an instance, and
    // mark every playing slot before the scan reaches their particles.
    core::Few<size_t, 32> order(pools.size(), poolOrder);
    for (size_t t = 0; t < pools.size(); ++t) {  // (an insertion sort: std::stable_sort may allocate)
        size_t k = t;
        for (; k > 0 && pools[order[k - 1]].live() > pools[t].live(); --k) order[k] = order[k - 1];
        order[k] = t;
    }
    for (size_t k = 0; k < order.size() && unseen > 0; ++k) {
        Pool& pool = pools[order[k]];
        const int column = pool.paramColumn.empty() ? -1 : pool.paramColumn.back();
        if (column < 0 || pool.live() == 0) continue;
        const float* instance = view<float>(pool.params.column(static_cast<size_t>(column), 0));
        const uint8_t* alive = view<uint8_t>(pool.alive.column);
        for (size_t r = 0, rows = pool.rows(); r < rows && unseen > 0; ++r) {
            if (!alive[r]) continue;
            // (A NaN fails every comparison: it marks slot 0, as core::instanceSlot reads it.)
            auto slot = static_cast<uint32_t>(instance[r] >= 0 ? std::min(instance[r], last) : 0.0f);
            if (!seen[slot]) seen[slot] = 1, --unseen;
        }
    }
    for (uint32_t slot = 0; slot < slots; ++slot) {
        InstanceSlot& i = instances[slot];
        if (i.life == InstanceLife::Finished || seen[slot]) continue;
        finishedInstances.push_back(handle(slot, i.generation));
        ++i.generation;
        // (its speed and pause are the handle's: a slot played again, or the system's own
        // restarted by a trigger, starts at 1 and playing)
        i.speed = 1;
        i.paused = false;
        setLife(slot, InstanceLife::Finished);
    }
}

}  // namespace detail

std::optional<std::string> System::checkBackend(const ir::Module& module, Backend& backend) {
    if (module.instanced() && !backend.memory().hostResident()) return std::string(core::kNoInstances);
    return std::nullopt;
}

std::optional<std::string> System::liveInstance(InstanceHandle instance, uint32_t& slot) const {
    const detail::State& s = *state_;
    if (!s.module.instanced())
        return std::string("the program is not instanced: it reads no `instance` (instance.pos, …), so its "
                           "instances could not be told apart (docs/embedding.md, \"Instances\")");
    slot = slotOf(instance);
    if (slot >= s.instances.size() || generationOf(instance) > s.instances[slot].generation)
        return fmt::format("there is no instance {:#x}", instance);
    if (generationOf(instance) < s.instances[slot].generation || s.instances[slot].life == InstanceLife::Finished)
        return fmt::format("instance {:#x} has finished", instance);
    return std::nullopt;
}

std::optional<std::string> System::play(std::span<const float> transform, InstanceHandle& out) {
    detail::State& s = *state_;
    uint32_t slot = 0;
    if (!s.module.instanced()) return liveInstance(0, slot);
    if (auto error = checkTransform(transform)) return error;
    // The lowest free slot past the system's own (it is the system's, played by fire()).
    slot = 1;
    while (slot < s.instances.size() && s.instances[slot].life != InstanceLife::Finished) ++slot;
    // (An instance's index is a float: whole numbers are exact below 2^24; and a record's
    // place in the table is a 32-bit index.)
    const size_t most = std::min<size_t>(size_t{1} << 24, (size_t{1} << 31) / s.instanceValues());
    if (slot >= most) return fmt::format("a system of this program plays at most {} instances at once", most);
    if (slot >= s.instances.size()) s.growInstances(std::max<size_t>(slot + 1, s.instances.size() * 2));
    Value* records = s.instanceRecord(slot);
    writeTransform(records, transform);
    // (Its externs the effect's: what the host set for all, not what a slot's last instance had.)
    std::copy(s.externs.begin(), s.externs.begin() + static_cast<std::ptrdiff_t>(s.module.externs.size()),
              records + core::kInstanceOwnValues);
    s.setLife(slot, InstanceLife::Playing);
    s.instances[slot].speed = 1;  // (not the slot's last instance's)
    s.instances[slot].paused = false;
    out = handle(slot, s.instances[slot].generation);
    start();
    s.ledger.settle(Wait::Yes);  // the rows the last step freed, before these objects take rows
    creation_->emitFromKernel(s.module.start, std::vector<Value>{Value::scalar(static_cast<float>(slot))}, kStartObject);
    creation_->drain(s.now);
    s.ledger.settle(Wait::No);
    drawing_->invalidate();
    return std::nullopt;
}

std::optional<std::string> System::setTransform(InstanceHandle instance, std::span<const float> transform) {
    uint32_t slot = 0;
    if (auto error = liveInstance(instance, slot)) return error;
    if (auto error = checkTransform(transform)) return error;
    writeTransform(state_->instanceRecord(slot), transform);
    ++state_->externsVersion;
    return std::nullopt;
}

std::optional<std::string> System::stop(InstanceHandle instance) {
    uint32_t slot = 0;
    if (auto error = liveInstance(instance, slot)) return error;
    if (state_->instances[slot].life == InstanceLife::Playing) state_->setLife(slot, InstanceLife::Stopped);
    return std::nullopt;
}

std::optional<std::string> System::kill(InstanceHandle instance) {
    uint32_t slot = 0;
    if (auto error = liveInstance(instance, slot)) return error;
    state_->setLife(slot, InstanceLife::Killed);
    return std::nullopt;
}

std::optional<std::string> System::fire(std::string_view trigger, std::span<const float> args, InstanceHandle instance) {
    uint32_t slot = 0;
    if (auto error = liveInstance(instance, slot)) return error;
    if (state_->instances[slot].life == InstanceLife::Killed)
        return fmt::format("instance {:#x} is killed: it creates nothing more", instance);
    if (auto error = checkFiring(trigger, args)) return error;
    return fireOn(trigger, args, slot);
}

std::optional<std::string> System::setInstanceExtern(InstanceHandle instance, int handle, std::span<const float> value) {
    uint32_t slot = 0;
    if (auto error = liveInstance(instance, slot)) return error;
    Value v;
    if (auto error = checkExtern(handle, value, v)) return error;
    state_->instanceRecord(slot)[core::kInstanceOwnValues + static_cast<size_t>(handle)] = v;
    ++state_->externsVersion;
    for (detail::TypeWork& w : state_->work) w.inStep.fresh = false;  // (a render kernel may read it)
    return std::nullopt;
}

std::optional<Value> System::instanceExtern(InstanceHandle instance, int handle) const {
    uint32_t slot = 0;
    if (liveInstance(instance, slot) || handle < 0 || static_cast<size_t>(handle) >= state_->module.externs.size())
        return std::nullopt;
    return state_->instanceRecord(slot)[core::kInstanceOwnValues + static_cast<size_t>(handle)];
}

InstanceLife System::life(InstanceHandle instance) const {
    uint32_t slot = 0;
    if (liveInstance(instance, slot)) return InstanceLife::Finished;
    return state_->instances[slot].life;
}

size_t System::instanceCount() const {
    size_t n = 0;
    for (const detail::InstanceSlot& i : state_->instances) n += i.life != InstanceLife::Finished;
    return n;
}

std::span<const InstanceHandle> System::finishedInstances() const { return state_->finishedInstances; }

}  // namespace psys::rt
