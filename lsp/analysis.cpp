#include "lsp/analysis.h"

#include <exception>

#include "driver/compile.h"
#include "frontend/frontend.h"
#include "frontend/loader.h"
#include "lsp/index_builder.h"

namespace psys::lsp {

const Occurrence* Analysis::at(int file, uint32_t offset) const {
    const Occurrence* best = nullptr;
    for (const Occurrence& o : occurrences) {
        if (o.range.file != file || offset < o.range.begin || offset > o.range.end) continue;
        if (!best || o.range.end - o.range.begin < best->range.end - best->range.begin) best = &o;
    }
    return best;
}

Analysis analyze(const std::string& path, std::string text) {
    Analysis a;
    a.sources = std::make_unique<SourceManager>();
    DiagnosticEngine diags(*a.sources);
    try {
        std::unique_ptr<ast::Program> program = loadProgramFromText(path, std::move(text), *a.sources, diags);
        if (program) {
            checkProgram(*program, diags);
            a.parsed = true;
            a.mainFile = program->main().file;
            buildIndex(*program, *a.sources, a);
            // What `psysc check` reports beyond the front end comes from the passes: an
            // integral with no closed form under @integrator(exact), a decay past the
            // integrator's stability limit. They run on a clean program only.
            if (diags.errorCount() == 0) compileProgram(program.get(), *a.sources, diags);
        }
    } catch (const std::exception& e) {
        // The front end's own failure must not end the editing session: it is reported
        // where the user looks, at the top of the file.
        diags.error({}, std::string("internal error in the front end: ") + e.what());
        a.parsed = false;
    }
    if (a.mainFile < 0)
        for (int f = 0; f < a.sources->count(); ++f)
            if (a.sources->file(f).path() == path) a.mainFile = f;
    a.diagnostics = diags.all();
    return a;
}

}  // namespace psys::lsp
