// Instances: one compiled effect played many times at once (docs/embedding.md,
// "Instances"). Every object of an instanced program — one that reads `instance` — carries
// the instance it belongs to as a hidden parameter, passed on to what it emits; the
// run-time keeps a table of the instances' records after the externs, and the `instance`
// op (core/ops.h) reads a record by that parameter. This is the table's one definition:
// the run-time writes it, the interpreter, the JIT and the GLSL backend read it.
//
// Table, in Values of four floats from externs[start] (start: the module's extern count E),
// each instance's record R = 4 + E values long:
//   [start]                   count (the records that follow; at least 1), 0, 0, 0
//   [start + 1 + R·i + k]     value k of instance i's record:
//     k = 0   the transform's x axis (its matrix's column 0), w: 1 while it emits, else 0
//     k = 1   its y axis, w: 1 once it is killed, else 0
//     k = 2   its z axis, w: the instance's index
//     k = 3   its position (column 3), w: 1
//     k = 4 + e   its value of extern e (an instanced program reads its externs here:
//                 each instance has its own, the effect's unless the host set one)
// An index outside the table (or NaN) reads the nearest record: a row never reads past it.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cmath>
#include <cstdint>
#include <string_view>

namespace psys::core {

constexpr int kInstanceOwnValues = 4;  // the transform's: before the externs'
// A record's values in a module of `externs` externs.
constexpr uint32_t instanceRecordValues(size_t externs) { return kInstanceOwnValues + static_cast<uint32_t>(externs); }
constexpr int kInstanceAxisX = 0, kInstanceAxisY = 1, kInstanceAxisZ = 2, kInstancePosition = 3;
// The flags in the records' w lanes.
constexpr int kInstanceEmitting = 0, kInstanceKilled = 1, kInstanceIndex = 2;

// The hidden parameter every object of an instanced program has, last among its
// parameters (a name no program can declare: `instance` is a built-in).
constexpr std::string_view kInstanceParam = "instance";

// What the glsl backend says of an instanced program: it does not play instances yet
// (its launches carry the externs, not the table).
constexpr std::string_view kNoInstances =
    "an instanced program (one that reads `instance`) runs on the CPU backends (llvm, interp, aot); the glsl "
    "backend does not play instances yet";

// Where value `value` of the record of the instance an f32 parameter names lies, from the
// table's start (its count's Value), records `stride` values long: the clamp every
// backend applies.
inline uint32_t instanceSlot(float instance, uint32_t count, int value, uint32_t stride) {
    count = std::max(count, 1u);
    uint32_t i = !(instance > 0) ? 0u : instance >= static_cast<float>(count) ? count - 1 : static_cast<uint32_t>(instance);
    return 1 + stride * i + static_cast<uint32_t>(value);
}

}  // namespace psys::core
