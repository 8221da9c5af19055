#include "driver/compile.h"

#include "frontend/frontend.h"
#include "ir/lower.h"

namespace psys {
namespace {

std::optional<ir::Module> compileProgram(const ast::Program* program, DiagnosticEngine& diags,
                                         const CompileOptions& options) {
    if (!program) return std::nullopt;
    ir::Module module = ir::lower(*program);
    opt::PassErrors errors;
    if (!opt::runPipeline(module, options.pipeline, errors)) {
        for (const std::string& e : errors) diags.error({}, e);
        return std::nullopt;
    }
    return module;
}

}  // namespace

std::optional<ir::Module> compileFile(const std::string& path, SourceManager& sources, DiagnosticEngine& diags,
                                      const CompileOptions& options) {
    auto program = checkFile(path, sources, diags);
    return compileProgram(program.get(), diags, options);
}

std::optional<ir::Module> compileText(const std::string& displayPath, std::string text, SourceManager& sources,
                                      DiagnosticEngine& diags, const CompileOptions& options) {
    auto program = checkText(displayPath, std::move(text), sources, diags);
    return compileProgram(program.get(), diags, options);
}

}  // namespace psys
