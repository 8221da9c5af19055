// Internal to lsp/: fills an Analysis's index from a checked (or partly checked) program.
#pragma once

#include "frontend/ast.h"
#include "lsp/analysis.h"

namespace psys::lsp {

void buildIndex(const ast::Program& program, const SourceManager& sources, Analysis& out);

// How declarations read in hovers and completion details: `object spark(ipos: vec3)`,
// `fn gravity(m: float) -> vec3`, `trigger boom(n: float)`.
std::string signature(const ast::ObjectDecl& object);
std::string signature(const ast::FnDecl& fn);
std::string signature(const ast::TriggerDecl& trigger);

}  // namespace psys::lsp
