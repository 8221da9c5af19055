// Lowering a checked program to IR (see lower.cpp for the evaluation-order rule): the
// layer between the front end and the IR, so that ir/ depends on nothing above it.
#pragma once

#include "frontend/ast.h"
#include "frontend/source.h"
#include "ir/ir.h"

namespace psys::lower {

// `program` must have passed the front end without errors; `sources` holds its files
// (instructions get their locations from it).
ir::Module lowerProgram(const ast::Program& program, const SourceManager& sources);

}  // namespace psys::lower
