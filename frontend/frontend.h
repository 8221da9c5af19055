// The front end in one call: load (parse every file, follow imports), resolve names,
// check types. What later stages receive is a fully annotated AST, or nothing.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "frontend/ast.h"
#include "frontend/diagnostics.h"

namespace psys {

// Returns the checked program, or null when there were errors (reported to `diags`).
// Warnings do not stop it.
std::unique_ptr<ast::Program> checkFile(const std::string& path, SourceManager& sources, DiagnosticEngine& diags);
std::unique_ptr<ast::Program> checkText(const std::string& displayPath, std::string text, SourceManager& sources,
                                        DiagnosticEngine& diags);

// For the language server, which checks a program again in parts (lsp/incremental.h).
struct CheckOptions {
    // The reports on the whole program (Diagnostic::report: functions and equations too
    // large once inlined, equations never used, objects never created) are made where the
    // program has no other error; with this, always, marked, for the caller to leave out
    // where the whole program turns out to have errors (publishedReports).
    bool allReports = false;
    // Where the program checked is part of one: whether something spawns in the rest (or a
    // trigger may), and what the rest declares (what a did-you-mean draws on): its
    // top-level declarations' names and kinds in the order declared, its nested objects'.
    bool spawnsElsewhere = false;
    std::vector<std::pair<std::string, ast::DeclKind>> declaredElsewhere = {};
    std::vector<std::string> nestedElsewhere = {};
};

// Resolves and type-checks an already loaded program in place.
void checkProgram(ast::Program& program, DiagnosticEngine& diags, CheckOptions options = {});

// `--emit=ast`: an indented, typed rendering of the checked tree.
std::string printAst(const ast::Program& program, const SourceManager& sources);

}  // namespace psys
