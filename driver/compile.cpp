#include "driver/compile.h"

#include <ostream>

#include "frontend/frontend.h"
#include "lower/lower.h"

namespace psys {

std::optional<ir::Module> compileProgram(const ast::Program* program, SourceManager& sources, DiagnosticEngine& diags,
                                         const CompileOptions& options) {
    if (!program) return std::nullopt;
    ir::Module module = lower::lowerProgram(*program, sources);
    const opt::PipelineOptions& pipeline = options.pipeline;
    if (pipeline.log && (pipeline.printAfterAll || !pipeline.printAfter.empty()))
        *pipeline.log << "; IR after lowering\n" << ir::print(module, pipeline.print);
    opt::PassErrors messages;
    bool ok = opt::runPipeline(module, pipeline, messages);
    for (const opt::PassMessage& m : messages) {
        if (m.warning) diags.warning(sourceRange(sources, m.loc), m.text);
        else diags.error(sourceRange(sources, m.loc), m.text);
    }
    if (!ok) return std::nullopt;
    return module;
}

SourceRange sourceRange(const SourceManager& sources, ir::Loc loc) {
    if (!loc.valid() || loc.file >= sources.count()) return {};
    const SourceFile& file = sources.file(loc.file);
    uint32_t begin = file.offset({loc.line, loc.column});
    return {loc.file, begin, begin + std::max<uint32_t>(loc.length, 1)};
}

std::optional<ir::Module> compileFile(const std::string& path, SourceManager& sources, DiagnosticEngine& diags,
                                      const CompileOptions& options) {
    auto program = checkFile(path, sources, diags);
    return compileProgram(program.get(), sources, diags, options);
}

std::optional<ir::Module> compileText(const std::string& displayPath, std::string text, SourceManager& sources,
                                      DiagnosticEngine& diags, const CompileOptions& options) {
    auto program = checkText(displayPath, std::move(text), sources, diags);
    return compileProgram(program.get(), sources, diags, options);
}

}  // namespace psys
