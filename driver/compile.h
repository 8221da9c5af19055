// The whole compiler as one call: source → checked AST → IR → passes. Used by psysc, the
// host library (and through it the viewer and the benchmarks) and the tests.
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "frontend/ast.h"
#include "frontend/diagnostics.h"
#include "ir/ir.h"
#include "opt/passes.h"

namespace psys {

struct CompileOptions {
    // The passes, and what they print: with `printAfter` or `printAfterAll` and a `log`,
    // the IR right after lowering is printed first.
    opt::PipelineOptions pipeline;
    // Called with the lowered module before the passes, and their messages: where the
    // chooser of integrators and steps under @tolerance (tune/tolerance.h) sets them.
    std::function<void(ir::Module&, opt::PassErrors&)> beforePasses;
    // Directories `import "std/…"` looks in first (SourceManager::libraryPath).
    std::vector<std::string> libraryPath;
};

// Returns the compiled module, or nullopt with the errors in `diags`. The passes' errors
// and warnings are reported at the instructions they concern.
std::optional<ir::Module> compileFile(const std::string& path, SourceManager& sources, DiagnosticEngine& diags,
                                      const CompileOptions& options = {});
std::optional<ir::Module> compileText(const std::string& displayPath, std::string text, SourceManager& sources,
                                      DiagnosticEngine& diags, const CompileOptions& options = {});

// A checked program (null: it had errors) through lowering and the passes.
std::optional<ir::Module> compileProgram(const ast::Program* program, SourceManager& sources, DiagnosticEngine& diags,
                                         const CompileOptions& options = {});

// An IR location as a source range (for diagnostics).
SourceRange sourceRange(const SourceManager& sources, ir::Loc loc);

}  // namespace psys
