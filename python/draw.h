// What the Python module reads of a system's draw of one type (python/draw.cpp): the
// System's columns(), points() and positions(), the system held by the caller.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstddef>

#include "psys/psys.h"

namespace psys::python {

namespace py = pybind11;

// The draw columns, each copied into a read-only array of its own.
py::dict drawColumns(psys_system* s, size_t type);
// The drawn points copied out (any backend): id, position (n×3), color (n×4), size, instance.
py::dict drawPoints(psys_system* s, size_t type);
// The drawn points' positions as an n×3 array.
py::array_t<float> drawPositions(psys_system* s, size_t type);

}  // namespace psys::python
