// psys_compile_file, psys_compile_string: a system compiled from source on a backend chosen
// by name (host::Session), and its hot reload. Only libpsys.so has these: a host of an
// ahead-of-time build links no compiler (capi/aot.cpp).
#include <optional>
#include <string>

#include <fmt/format.h>

#include "capi/handle.h"
#include "host/large_stack.h"
#include "host/session.h"

using psys::capi::guarded;
using psys::capi::makeError;
using psys::capi::nullArgument;
using psys::capi::OwnedDiagnostic;
using psys::Severity;
using psys::Diagnostic;
using psys::DiagnosticEngine;
using psys::SourceFile;
using psys::LineColumn;
namespace host = psys::host;

namespace {

psys_severity severityOf(Severity s) {
    switch (s) {
        case Severity::Error: return PSYS_SEVERITY_ERROR;
        case Severity::Warning: return PSYS_SEVERITY_WARNING;
        case Severity::Note: return PSYS_SEVERITY_NOTE;
        case Severity::Remark: return PSYS_SEVERITY_REMARK;
    }
    return PSYS_SEVERITY_ERROR;
}

// The diagnostics an engine holds: errors and warnings, or warnings only.
std::vector<OwnedDiagnostic> diagnosticsOf(const DiagnosticEngine& engine, bool errors) {
    std::vector<OwnedDiagnostic> out;
    for (const Diagnostic& d : engine.all()) {
        if (d.severity != Severity::Warning && !(errors && d.severity == Severity::Error)) continue;
        OwnedDiagnostic o;
        o.severity = severityOf(d.severity);
        o.message = d.message;
        if (d.range.valid() && d.range.file < engine.sources().count()) {
            const SourceFile& f = engine.sources().file(d.range.file);
            // line and column are where the message's `line:column` and caret point (the
            // focus: a binary operator whose operands disagree), the range around it.
            LineColumn end = f.lineColumn(d.range.end);
            LineColumn at = f.lineColumn(d.focus.value_or(d.range.begin));
            o.file = f.path();
            o.line = at.line;
            o.column = at.column;
            o.endLine = end.line;
            o.endColumn = end.column;
        }
        out.push_back(std::move(o));
    }
    return out;
}

// Compiles on a thread with a large stack (the compiler recurses as deep as expressions
// nest: host/large_stack.h); the module or the error with the diagnostics.
psys_error* compileModule(const std::string& path, const psys::CompileOptions& options, const std::string* text,
                          std::optional<psys::ir::Module>& module, std::vector<OwnedDiagnostic>& warnings) {
    host::CompileResult result;
    host::runWithLargeStack([&] {
        result = host::compile(path, options, module, text);
        return 0;
    });
    result.diagnostics->setProgram("psys");  // the library's (`psys: error: cannot read …`), not psysc's
    if (!module) return makeError(result.text(), diagnosticsOf(*result.diagnostics, true));
    warnings = diagnosticsOf(*result.diagnostics, false);
    return nullptr;
}

struct CompiledSystem final : psys_system {
    std::unique_ptr<host::Session> session;
    bool fromString = false;

    psys::rt::System& system() override { return session->system(); }

    psys_error* reload(const char* source) override {
        if (!source && fromString)
            return makeError("psys_reload: the system was compiled from a string: its new source is needed");
        std::string text = source ? source : "";
        host::Session::Candidate candidate;
        std::vector<OwnedDiagnostic> compiled;
        if (psys_error* e = compileModule(session->path(), session->options().compile, source ? &text : nullptr,
                                          candidate.module, compiled))
            return e;  // the running system goes on untouched
        session->adopt(std::move(candidate));
        warnings = std::move(compiled);
        describe();
        return nullptr;
    }
};

psys_error* open(const char* function, const std::string& path, const std::string* text, const psys_options* given,
                 psys_system** out) {
    if (!out) return nullArgument(function, "the place for the system (out)");
    *out = nullptr;
    psys::capi::Options o;
    if (psys_error* e = psys::capi::readOptions(function, given, o)) return e;
    host::SessionOptions so;
    so.backend.name = o.backend;
    so.backend.math = o.math;
    so.system = o.system;
    so.compile.pipeline.optimize = o.optimize;
    so.compile.libraryPath = o.libraryPath;
    so.backend.jitCache = o.jitCache;
    so = host::Session::resolved(so);
    auto s = std::make_unique<CompiledSystem>();
    std::optional<psys::ir::Module> module;
    if (psys_error* e = compileModule(path, so.compile, text, module, s->warnings)) return e;
    std::string error;
    s->session = host::Session::start(path, so, std::move(*module), error);
    if (!s->session) return makeError(fmt::format("{}: {}", function, error));
    s->fromString = text != nullptr;
    s->describe();
    *out = s.release();
    return nullptr;
}

}  // namespace

extern "C" {

psys_error* psys_compile_file(const char* path, const psys_options* options, psys_system** out) {
    if (out) *out = nullptr;
    if (!path) return nullArgument("psys_compile_file", "the path");
    return guarded("psys_compile_file", [&] { return open("psys_compile_file", path, nullptr, options, out); });
}

psys_error* psys_compile_string(const char* source, const char* name, const psys_options* options, psys_system** out) {
    if (out) *out = nullptr;
    if (!source) return nullArgument("psys_compile_string", "the source");
    return guarded("psys_compile_string", [&] {
        std::string text = source;
        return open("psys_compile_string", name ? name : "<string>", &text, options, out);
    });
}

}  // extern "C"
