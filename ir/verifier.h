// Checks the IR's invariants: operands defined before use (except through the temporal
// constructs that may close a cycle, and only before they are lowered), arities, types,
// attribute ranges and yields. Run after every pass in debug builds and in tests.
#pragma once

#include <string>
#include <vector>

#include "ir/ir.h"

namespace psys::ir {

// Every problem found, as "object NAME, kernel KIND, %N: what"; empty when the module is
// well formed.
std::vector<std::string> verify(const Module& module);

}  // namespace psys::ir
