#include "capi/error.h"

namespace psys::capi {

psys_diagnostic OwnedDiagnostic::view() const {
    return {severity, file.c_str(), line, column, endLine, endColumn, message.c_str()};
}

psys_error* makeError(std::string message, std::vector<OwnedDiagnostic> diagnostics) {
    if (message.empty()) message = "error";
    return new psys_error{std::move(message), std::move(diagnostics)};
}

psys_error* nullArgument(const char* function, const char* what) {
    return makeError(std::string(function) + ": " + what + " is NULL");
}

psys_error* orError(const char* function, const std::optional<std::string>& error) {
    return error ? makeError(std::string(function) + ": " + *error) : nullptr;
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
