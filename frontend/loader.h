// Loading a program: the main file and, transitively, every file it imports.
//
// An import path is relative to the importing file. Each file is loaded once however
// often it is imported (by its canonical path); an import cycle is an error that names
// the chain of files.
#pragma once

#include <memory>
#include <string>

#include "frontend/ast.h"
#include "frontend/diagnostics.h"

namespace psys {

// Returns null when the main file cannot be read or any file has syntax errors.
std::unique_ptr<ast::Program> loadProgram(const std::string& mainPath, SourceManager& sources, DiagnosticEngine& diags);

// The same for a main file given as text (tests, the viewer's editor buffer); imports are
// resolved relative to the directory of `displayPath`.
std::unique_ptr<ast::Program> loadProgramFromText(const std::string& displayPath, std::string text,
                                                  SourceManager& sources, DiagnosticEngine& diags);

}  // namespace psys
