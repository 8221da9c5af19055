#include "capi/error.h"

namespace psys::capi {

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

}  // namespace

psys_diagnostic OwnedDiagnostic::view() const {
    return {severity, file.c_str(), line, column, endLine, endColumn, message.c_str()};
}

std::vector<OwnedDiagnostic> diagnosticsOf(const DiagnosticEngine& engine, bool errors) {
    std::vector<OwnedDiagnostic> out;
    for (const Diagnostic& d : engine.all()) {
        if (d.severity != Severity::Warning && !(errors && d.severity == Severity::Error)) continue;
        OwnedDiagnostic o;
        o.severity = severityOf(d.severity);
        o.message = d.message;
        if (d.range.valid() && d.range.file < engine.sources().count()) {
            const SourceFile& f = engine.sources().file(d.range.file);
            LineColumn begin = f.lineColumn(d.range.begin), end = f.lineColumn(d.range.end);
            o.file = f.path();
            o.line = begin.line;
            o.column = begin.column;
            o.endLine = end.line;
            o.endColumn = end.column;
        }
        out.push_back(std::move(o));
    }
    return out;
}

psys_error* makeError(std::string message, std::vector<OwnedDiagnostic> diagnostics) {
    if (message.empty()) message = "error";
    return new psys_error{std::move(message), std::move(diagnostics)};
}

psys_error* nullArgument(const char* function, const char* what) {
    return makeError(std::string(function) + ": " + what + " is NULL");
}

}  // namespace psys::capi

using psys::capi::OwnedDiagnostic;

extern "C" {

const char* psys_error_message(const psys_error* error) { return error ? error->message.c_str() : ""; }

size_t psys_error_diagnostic_count(const psys_error* error) { return error ? error->diagnostics.size() : 0; }

int psys_error_diagnostic(const psys_error* error, size_t index, psys_diagnostic* out) {
    if (!error || !out || index >= error->diagnostics.size()) return -1;
    *out = error->diagnostics[index].view();
    return 0;
}

void psys_error_free(psys_error* error) { delete error; }

}  // extern "C"
