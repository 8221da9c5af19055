#include "lsp/analysis.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cmath>
#include <exception>

#include <fmt/format.h>

#include "driver/compile.h"
#include "interp/interpreter.h"
#include "frontend/frontend.h"
#include "frontend/loader.h"
#include "lsp/incremental.h"
#include "lsp/index_builder.h"
#include "lsp/salvage.h"
#include "opt/passes.h"
#include "tune/tolerance.h"

namespace psys::lsp {

const Occurrence* Analysis::at(int file, uint32_t offset) const {
    const Occurrence* best = nullptr;
    for (const Occurrence& o : occurrences) {
        if (o.range.file != file || offset < o.range.begin || offset > o.range.end) continue;
        if (!best || o.range.end - o.range.begin < best->range.end - best->range.begin) best = &o;
    }
    return best;
}

namespace {

// "1/240 s" where a step is a whole fraction of a second, else its seconds.
std::string stepText(float step) {
    double per = 1.0 / step;
    if (std::abs(per - std::round(per)) < 1e-3 * per) return fmt::format("1/{:g} s", std::round(per));
    return fmt::format("{:g} s", step);
}

// How each object of the main file that integrates is solved: its method (the one rule,
// opt::methodOf) and its step, from the compiled module.
void methodHints(const ir::Module& module, Analysis& a) {
    for (const ir::Object& o : module.objects) {
        SourceRange at = sourceRange(*a.sources, o.loc);
        bool integrates = false;
        for (SourceRange r : a.integrating) integrates |= r.file == at.file && r.begin == at.begin;
        if (!integrates) continue;
        core::Integrator method = opt::methodOf(o, {});
        std::string label = std::string(core::integratorName(method));
        if (method == core::Integrator::Bs3)  // its own steps, up to four tries an update (or sub-step)
            label += o.attributes.step > 0 ? ", adaptive, sub-steps of " + stepText(o.attributes.step)
                                           : ", adaptive within each update";
        else
            label += o.attributes.step > 0 ? ", step " + stepText(o.attributes.step) : ", a step per update";
        if (o.attributes.precision == core::Precision::Double) label += ", state in double";
        if (o.attributes.tolerance > 0) label += fmt::format(" (chosen for @tolerance({:g}))", o.attributes.tolerance);
        a.hints.push_back({at, label, 2});
    }
}

}  // namespace

Analysis analyze(const std::string& path, std::string text, const AnalyzeOptions& options) {
    auto started = std::chrono::steady_clock::now();
    const std::atomic<bool>* cancelled = options.cancelled;
    auto stop = [&] { return cancelled && cancelled->load(std::memory_order_relaxed); };
    if (options.previous && options.cache && !options.passes)
        if (auto again = reanalyze(path, text, *options.previous, options)) return std::move(*again);
    Analysis a;
    a.sources = std::make_unique<SourceManager>();
    DiagnosticEngine diags(*a.sources);
    diags.setLimit(kMaxKept);
    size_t passDiagnostics = SIZE_MAX;  // where the passes' diagnostics start
    try {
        std::unique_ptr<ast::Program> program = loadProgramFromText(path, std::move(text), *a.sources, diags, options.open, options.cache);
        if (program && stop()) return a;  // a newer text is on its way: this one is not wanted
        if (program) {
            // (Every report on the whole program made, and published where a whole check
            // makes it: the next text's analysis may carry it.)
            checkProgram(*program, diags, {.allReports = true});
            a.parsed = true;
            a.mainFile = program->main().file;
            buildIndex(*program, *a.sources, a);
            a.instanced = program->instanced;
            if (options.cache)
                if (auto pieces = options.cache->pieces(a.sources->file(a.mainFile).text())) a.pieces = std::move(*pieces);
            // What `psysc check` reports beyond the front end comes from the passes: an
            // integral with no closed form under @integrator(exact), a decay past the
            // integrator's stability limit. They run on a clean program only.
            // Under @tolerance the chooser runs its trials on the interpreter (what the
            // hints and warnings say is what `psysc check` says, give or take fast maths).
            // An editor never waits long on them: a fortieth of `psysc check`'s budget of
            // steps (about 2 s on the interpreter at most: didOpen and a request on an edited
            // text analyse at once), and a newer text stops the ones in the background.
            CompileOptions compile;
            interp::Interpreter trials;
            tune::TuneOptions tune;
            tune.budget /= 40;
            tune.cancelled = cancelled;
            compile.beforePasses = [&](ir::Module& module, opt::PassErrors& messages) {
                if (!stop()) tune::chooseMethods(module, trials, tune, messages);
            };
            passDiagnostics = diags.all().size();
            a.passHints = a.hints.size();
            if (options.passes && diags.errorCount() == 0 && !stop()) {
                auto passesStarted = std::chrono::steady_clock::now();
                if (auto module = compileProgram(program.get(), *a.sources, diags, compile)) methodHints(*module, a);
                a.passesRan = true;
                a.passesMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - passesStarted).count();
            }
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
    for (int f = 0; f < a.sources->count(); ++f)
        if (f != a.mainFile) a.imported.insert(sourceKey(a.sources->file(f).path()));
    {
        int hiddenErrors = diags.hiddenErrors(), hiddenWarnings = diags.hiddenWarnings();
        std::vector<Diagnostic> all = diags.take();
        size_t front = std::min(passDiagnostics, all.size());
        std::vector<Diagnostic> passes(std::make_move_iterator(all.begin() + long(front)), std::make_move_iterator(all.end()));
        all.resize(front);
        publishable(a, std::move(all), std::move(passes), hiddenErrors, hiddenWarnings);
    }
    if (options.salvage && !a.parsed && !stop())
        if (auto s = salvaged(path, a, options)) a = std::move(*s);
    a.milliseconds = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started).count();
    return a;
}

std::optional<Analysis> salvaged(const std::string& path, const Analysis& broken, const AnalyzeOptions& options) {
    // Only where every error is the main file's own (an import's would be numbered apart).
    std::vector<uint32_t> errors;
    for (const Diagnostic& d : broken.diagnostics) {
        if (d.severity != Severity::Error) continue;
        if (d.range.file != broken.mainFile || broken.mainFile < 0) return std::nullopt;
        errors.push_back(d.range.begin);
    }
    const std::string& text = broken.sources->file(broken.mainFile).text();
    auto blanked = blankBroken(text, errors);
    if (!blanked) return std::nullopt;
    AnalyzeOptions again = options;
    again.salvage = false;
    again.previous = nullptr;
    Analysis s = analyze(path, *blanked, again);
    if (!s.parsed || s.mainFile < 0) return std::nullopt;
    // The index over the text as it is (the blanked one has spaces where the broken
    // declarations are, so every offset is the same); the diagnostics the text's own.
    auto sources = std::make_unique<SourceManager>();
    for (int f = 0; f < s.sources->count(); ++f) {
        const SourceFile& file = s.sources->file(f);
        sources->add(file.path(), f == s.mainFile ? text : file.text());
        sources->setImportedAt(f, s.sources->importedAt(f));
    }
    s.sources = std::move(sources);
    s.diagnostics = broken.diagnostics;
    s.passesRan = false;
    s.passDiagnostics = s.diagnostics.size();
    s.hiddenErrors = broken.hiddenErrors;
    s.hiddenWarnings = broken.hiddenWarnings;
    s.recovered = true;
    s.frontEnd = nullptr;
    s.imported.insert(broken.imported.begin(), broken.imported.end());
    return s;
}

}  // namespace psys::lsp
