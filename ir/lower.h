// Lowering a checked program to IR (see lower.cpp for the evaluation-order rule).
#pragma once

#include "frontend/ast.h"
#include "frontend/source.h"
#include "ir/ir.h"

namespace psys::ir {

// `program` must have passed the front end without errors; `sources` holds its files
// (instructions get their locations from it).
Module lower(const ast::Program& program, const SourceManager& sources);

}  // namespace psys::ir
