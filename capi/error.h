// The C API's errors: a value a call returns, with a message and, for a compilation, its
// diagnostics as plain data (file, line, column, text) that outlive the compiler's own.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "psys/psys.h"
#include "rt/host_allocator.h"

namespace psys::capi {

// One diagnostic with its strings owned (psys_diagnostic points into them).
struct OwnedDiagnostic {
    psys_severity severity = PSYS_SEVERITY_ERROR;
    std::string file, message;
    uint32_t line = 0, column = 0, endLine = 0, endColumn = 0;
    psys_diagnostic view() const;
};

// A new error (owned by the caller, freed with psys_error_free).
psys_error* makeError(std::string message, std::vector<OwnedDiagnostic> diagnostics = {});

// "psys_step: the system is NULL": the message of a null argument.
psys_error* nullArgument(const char* function, const char* what);

// "psys_step: …" where a call of the run-time said why it refused, else no error.
psys_error* orError(const char* function, const std::optional<std::string>& error);

// Runs `body` and turns what it throws into an error: no exception crosses into C.
template <typename Body>
psys_error* guarded(const char* function, Body&& body) {
    try {
        return body();
    } catch (const rt::HostOutOfMemory& e) {  // (the host's allocator said no: not the library's fault)
        return makeError(std::string(function) + ": " + e.what());
    } catch (const std::exception& e) {
        return makeError(std::string(function) + ": internal error: " + e.what());
    } catch (...) {
        return makeError(std::string(function) + ": internal error");
    }
}

}  // namespace psys::capi

struct psys_error {
    std::string message;
    std::vector<psys::capi::OwnedDiagnostic> diagnostics;
};
