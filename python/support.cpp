// The Python module's errors and conversions (python/support.h).
#include "python/support.h"

#include <algorithm>
#include <stdexcept>

namespace psys::python {

// The Python exceptions (psys/__init__.py defines them; set when the package imports us).
py::object& compileErrorType() {
    static py::object* type = new py::object();
    return *type;
}
py::object& errorType() {
    static py::object* type = new py::object();
    return *type;
}
// psys.UnknownNameError (a psys.Error and a KeyError) and psys.ValueTypeError (a
// psys.Error and a TypeError).
py::object& unknownNameType() {
    static py::object* type = new py::object();
    return *type;
}
py::object& valueTypeType() {
    static py::object* type = new py::object();
    return *type;
}

py::dict diagnostic(const psys_diagnostic& d) {
    static const char* severities[] = {"error", "warning", "note", "remark"};
    py::dict out;
    out["severity"] = severities[d.severity];
    out["file"] = d.file;
    out["line"] = d.line;
    out["column"] = d.column;
    out["end_line"] = d.end_line;
    out["end_column"] = d.end_column;
    out["message"] = d.message;
    return out;
}

// Raises the error (freed) as CompileError when it has diagnostics, else Error.
void check(psys_error* e) {
    if (!e) return;
    std::string message = psys_error_message(e);
    py::list diagnostics;
    psys_diagnostic d;
    for (size_t i = 0; psys_error_diagnostic(e, i, &d) == 0; ++i) diagnostics.append(diagnostic(d));
    psys_error_free(e);
    py::object type = py::len(diagnostics) ? compileErrorType() : errorType();
    if (!type) throw std::runtime_error(message);
    py::object error = type(message);
    error.attr("diagnostics") = diagnostics;
    PyErr_SetObject(type.ptr(), error.ptr());
    throw py::error_already_set();
}

[[noreturn]] void raise(PyObject* type, const std::string& message) {
    PyErr_SetString(type, message.c_str());
    throw py::error_already_set();
}

// A value as floats: a number, a bool, a sequence of them, or a NumPy array of any shape
// (a 0-d one included), flattened.
std::vector<float> floats(const py::object& values, const char* what) {
    if (py::isinstance<py::str>(values) || py::isinstance<py::bytes>(values) || values.is_none())
        raise(PyExc_TypeError, std::string(what) + " takes a number or a sequence of numbers, not " +
                                   py::str(py::type::of(values).attr("__name__")).cast<std::string>());
    py::array_t<float, py::array::c_style | py::array::forcecast> a;
    try {
        a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(values);
    } catch (const py::error_already_set&) {
    }
    if (!a)
        raise(PyExc_TypeError, std::string(what) + " takes a number or a sequence of numbers, not " +
                                   py::str(py::type::of(values).attr("__name__")).cast<std::string>());
    return {a.data(), a.data() + a.size()};
}

// The C API reads a source up to its first NUL: one inside is the error psysc gives for
// it (CompileError, at its line and column), not a program cut short.
void refuseNul(const std::string& source, const std::string& name) {
    size_t at = source.find('\0');
    if (at == std::string::npos) return;
    size_t lineStart = source.rfind('\n', at);
    lineStart = lineStart == std::string::npos ? 0 : lineStart + 1;
    auto line = static_cast<unsigned>(std::count(source.begin(), source.begin() + static_cast<long>(at), '\n') + 1);
    auto column = static_cast<unsigned>(at - lineStart + 1);
    const char* message = "unexpected character U+0000";
    psys_diagnostic d{};
    d.severity = PSYS_SEVERITY_ERROR;
    d.file = name.c_str();
    d.line = line;
    d.column = column;
    d.end_line = line;
    d.end_column = column + 1;
    d.message = message;
    py::list diagnostics;
    diagnostics.append(diagnostic(d));
    py::object error = compileErrorType()(name + ":" + std::to_string(line) + ":" + std::to_string(column) +
                                          ": error: " + message);
    error.attr("diagnostics") = diagnostics;
    PyErr_SetObject(compileErrorType().ptr(), error.ptr());
    throw py::error_already_set();
}

[[noreturn]] void raiseAs(const py::object& type, const std::string& message) {
    PyErr_SetObject(type.ptr(), type(message).ptr());
    throw py::error_already_set();
}

std::string reprOf(const py::object& value) { return py::repr(value).cast<std::string>(); }

}  // namespace psys::python
