// Lowering a checked program to IR (see lower.cpp for the evaluation-order rule).
#pragma once

#include "frontend/ast.h"
#include "ir/ir.h"

namespace psys::ir {

// `program` must have passed the front end without errors.
Module lower(const ast::Program& program);

}  // namespace psys::ir
