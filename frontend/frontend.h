// The front end in one call: load (parse every file, follow imports), resolve names,
// check types. What later stages receive is a fully annotated AST, or nothing.
#pragma once

#include <memory>
#include <string>

#include "frontend/ast.h"
#include "frontend/diagnostics.h"

namespace psys {

// Returns the checked program, or null when there were errors (reported to `diags`).
// Warnings do not stop it.
std::unique_ptr<ast::Program> checkFile(const std::string& path, SourceManager& sources, DiagnosticEngine& diags);
std::unique_ptr<ast::Program> checkText(const std::string& displayPath, std::string text, SourceManager& sources,
                                        DiagnosticEngine& diags);

// What the rest of a program holds where `checkProgram` is given a part of it (the
// language server re-checking the declarations an edit touched, lsp/incremental.h): the
// reports about the whole program (equations never used, objects never created, functions
// too large once inlined) are made only where it has no errors, and "never created" only
// where something spawns.
struct CheckedElsewhere {
    int errors = 0;
    bool spawns = false;
};

// Resolves and type-checks an already loaded program in place.
void checkProgram(ast::Program& program, DiagnosticEngine& diags, CheckedElsewhere elsewhere = {});

// `--emit=ast`: an indented, typed rendering of the checked tree.
std::string printAst(const ast::Program& program, const SourceManager& sources);

}  // namespace psys
