#include "frontend/frontend.h"

#include "frontend/checker.h"
#include "frontend/loader.h"

namespace psys {

void checkProgram(ast::Program& program, DiagnosticEngine& diags, CheckOptions options) {
    detail::Checker(program, diags, options).run();
}

namespace {

std::unique_ptr<ast::Program> finish(std::unique_ptr<ast::Program> program, DiagnosticEngine& diags) {
    if (!program) return nullptr;
    checkProgram(*program, diags);
    return diags.errorCount() == 0 ? std::move(program) : nullptr;
}

}  // namespace

std::unique_ptr<ast::Program> checkFile(const std::string& path, SourceManager& sources, DiagnosticEngine& diags) {
    return finish(loadProgram(path, sources, diags), diags);
}

std::unique_ptr<ast::Program> checkText(const std::string& displayPath, std::string text, SourceManager& sources,
                                        DiagnosticEngine& diags) {
    return finish(loadProgramFromText(displayPath, std::move(text), sources, diags), diags);
}

}  // namespace psys
