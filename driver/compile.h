// The whole compiler as one call: source → checked AST → IR → passes. Used by psysc,
// the tests, the benchmarks and (later) the viewer.
#pragma once

#include <optional>
#include <string>

#include "frontend/diagnostics.h"
#include "ir/ir.h"
#include "opt/passes.h"

namespace psys {

struct CompileOptions {
    opt::PipelineOptions pipeline;
};

// Returns the compiled module, or nullopt with the errors in `diags` (a pass's errors are
// reported without a location).
std::optional<ir::Module> compileFile(const std::string& path, SourceManager& sources, DiagnosticEngine& diags,
                                      const CompileOptions& options = {});
std::optional<ir::Module> compileText(const std::string& displayPath, std::string text, SourceManager& sources,
                                      DiagnosticEngine& diags, const CompileOptions& options = {});

}  // namespace psys
