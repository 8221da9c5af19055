// Parsing one .psys file into an AST module (ANTLR4 parser generated from grammar/Psys.g4).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "frontend/ast.h"
#include "frontend/diagnostics.h"

namespace psys {

// Returns null when the file has syntax errors (they are reported to `diags`, several per
// file: the parser recovers and goes on).
std::unique_ptr<ast::Module> parseModule(int file, const SourceManager& sources, DiagnosticEngine& diags);

// Character index (ANTLR decodes UTF-8 into code points) → byte offset, plus one past the end.
std::vector<uint32_t> codePointOffsets(const std::string& text);

}  // namespace psys
