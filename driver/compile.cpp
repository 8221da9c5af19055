#include "driver/compile.h"

#include <algorithm>
#include <ostream>

#include "frontend/frontend.h"
#include "lower/lower.h"

namespace psys {

namespace {

// An object by its IR name: `outer.inner` for an object declared in another.
const ast::ObjectDecl* findObject(const ast::Program& program, const std::string& name) {
    const ast::ObjectDecl* found = nullptr;
    size_t from = 0;
    while (from <= name.size()) {
        size_t dot = std::min(name.find('.', from), name.size());
        std::string part = name.substr(from, dot - from);
        const ast::ObjectDecl* next = nullptr;
        if (!found) {
            for (const auto& module : program.modules)
                for (const auto& decl : module->decls)
                    if (decl->kind == ast::DeclKind::Object && static_cast<const ast::ObjectDecl&>(*decl).name == part)
                        next = static_cast<const ast::ObjectDecl*>(decl.get());
        } else {
            for (const auto& child : found->children)
                if (child->name == part) next = child.get();
        }
        if (!next) return nullptr;
        found = next;
        from = dot + 1;
    }
    return found;
}

// `@name(…)` put on `object`: replacing its own @name, or on a line of its own above it.
FixIt attributeFix(const ast::ObjectDecl& object, const SourceManager& sources, const std::string& attribute) {
    std::string name = attribute.substr(1, attribute.find('(') - 1);
    for (const ast::Attribute& a : object.attributes)
        if (a.name == name) return {"Use " + attribute, a.range, attribute};
    const SourceFile& file = sources.file(object.range.file);
    uint32_t at = object.range.begin;
    std::string_view line = file.lineText(file.lineColumn(at).line);
    std::string indent(line.substr(0, line.find_first_not_of(" \t")));
    return {"Add " + attribute, {object.range.file, at, at}, attribute + "\n" + indent};
}

}  // namespace

std::optional<ir::Module> compileProgram(const ast::Program* program, SourceManager& sources, DiagnosticEngine& diags,
                                         const CompileOptions& options) {
    if (!program) return std::nullopt;
    ir::Module module = lower::lowerProgram(*program, sources);
    const opt::PipelineOptions& pipeline = options.pipeline;
    if (pipeline.log && (pipeline.printAfterAll || !pipeline.printAfter.empty()))
        *pipeline.log << "; IR after lowering\n" << ir::print(module, pipeline.print);
    opt::PassErrors messages;
    if (options.beforePasses) options.beforePasses(module, messages);
    bool ok = !messages.hasErrors() && opt::runPipeline(module, pipeline, messages);
    for (const opt::PassMessage& m : messages) {
        Diagnostic& d = m.warning ? diags.warning(sourceRange(sources, m.loc), m.text)
                                  : diags.error(sourceRange(sources, m.loc), m.text);
        if (const ast::ObjectDecl* object = m.attributes.empty() ? nullptr : findObject(*program, m.object))
            for (const std::string& attribute : m.attributes) d.fixes.push_back(attributeFix(*object, sources, attribute));
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
    sources.setLibraryPath({options.libraryPath.begin(), options.libraryPath.end()});
    auto program = checkFile(path, sources, diags);
    return compileProgram(program.get(), sources, diags, options);
}

std::optional<ir::Module> compileText(const std::string& displayPath, std::string text, SourceManager& sources,
                                      DiagnosticEngine& diags, const CompileOptions& options) {
    sources.setLibraryPath({options.libraryPath.begin(), options.libraryPath.end()});
    auto program = checkText(displayPath, std::move(text), sources, diags);
    return compileProgram(program.get(), sources, diags, options);
}

}  // namespace psys
