// What the Python module's parts share (python/module.cpp, python/draw.cpp): the
// exceptions psys/__init__.py defines, a C API error raised as one of them, and values
// read from Python objects.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>
#include <vector>

#include "psys/psys.h"

namespace psys::python {

namespace py = pybind11;

// The Python exceptions (set when the package imports the module): psys.CompileError,
// psys.Error, psys.UnknownNameError (a psys.Error and a KeyError) and psys.ValueTypeError
// (a psys.Error and a TypeError).
py::object& compileErrorType();
py::object& errorType();
py::object& unknownNameType();
py::object& valueTypeType();

py::dict diagnostic(const psys_diagnostic& d);
// Raises the error (freed) as CompileError when it has diagnostics, else Error.
void check(psys_error* e);
[[noreturn]] void raise(PyObject* type, const std::string& message);
[[noreturn]] void raiseAs(const py::object& type, const std::string& message);
std::string reprOf(const py::object& value);
// A value as floats: a number, a bool, a sequence of them, or a NumPy array of any shape
// (a 0-d one included), flattened.
std::vector<float> floats(const py::object& values, const char* what);
// The C API reads a source up to its first NUL: one inside is the error psysc gives for
// it (CompileError, at its line and column), not a program cut short.
void refuseNul(const std::string& source, const std::string& name);

}  // namespace psys::python
