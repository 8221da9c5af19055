// The IR's text form: `psysc --emit=ir` prints it, ir/parser reads it back.
//
//   object rocket(ivel: vec3)
//     state vel_integral: vec3 zero
//     emit spark rate
//     kernel update
//       %0 = state.vec3 #0                ; one instruction a line, numbered in order
//       %1 = const.vec3 0 -2.946 0
//       %2 = dt.f32
//       %3 = splat.vec3 %2
//       %4 = mul.vec3 %1, %3
//       %5 = add.vec3 %0, %4              ; vel
//       yield state #0 = %5
//     end
//   end
//
// `#n` is an instruction's index attribute, `^n` its parent depth, `<a b>` shuffle lanes;
// a `; name` comment keeps the equation a value came from. With `locations`, each
// instruction says where it came from: `loc(fire.psys:4:25)` (file, line, column).
#pragma once

#include <string>

#include "ir/ir.h"

namespace psys::ir {

struct PrintOptions {
    bool locations = false;
    const std::vector<std::string>* files = nullptr;  // Module::files, for locations
};

std::string print(const Module& module, PrintOptions options = {});
std::string print(const Object& object, PrintOptions options = {});
std::string print(const Kernel& kernel, int indent = 0, PrintOptions options = {});
std::string yieldKindName(YieldKind kind);

}  // namespace psys::ir
