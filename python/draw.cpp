// What the Python module reads of a system's draw (python/draw.h): copies of its columns,
// its points and its positions.
#include "python/draw.h"

#include <algorithm>
#include <cstring>
#include <vector>

#include "python/support.h"

namespace psys::python {

// The draw columns, each copied into an array of its own (read-only); a constant
// column as one value repeated (stride 0). Not views of the system's memory: a step
// that grows a pool moves it and a reload frees it, and an array read after either
// read freed memory (a crash on a large pool, old values or NaN on a small one).
// A copy is a memcpy a column (about 3 ms for 13 columns of 262k rows).
py::dict drawColumns(psys_system* s, size_t type) {
    psys_draw d;
    check(psys_get_draw(s, type, &d));
    py::dict out;
    auto add = [&](const char* name, const psys_column& c, bool ids) {
        auto rows = static_cast<py::ssize_t>(d.rows);
        if (c.gl_buffer) {
            PyErr_SetString(errorType().ptr(), "the columns are GL buffers on the glsl backend: points() copies them");
            throw py::error_already_set();
        }
        py::array a;
        if (c.data && ids) {
            py::array_t<uint32_t> copy(rows);
            if (rows) std::memcpy(copy.mutable_data(), c.data, d.rows * sizeof(uint32_t));
            a = copy;
        } else if (c.data) {
            py::array_t<float> copy(rows);
            if (rows) std::memcpy(copy.mutable_data(), c.data, d.rows * sizeof(float));
            a = copy;
        } else {
            auto one = py::array_t<float>(1);
            one.mutable_at(0) = c.constant;
            a = py::array_t<float>({rows}, {py::ssize_t{0}}, one.data(), one);
        }
        a.attr("setflags")(py::arg("write") = false);  // what the system drew: read only
        out[name] = a;
    };
    add("visible", d.visible, false);
    add("id", d.ids, true);
    const char* xyz[] = {"x", "y", "z"};
    const char* rgba[] = {"r", "g", "b", "a"};
    for (int k = 0; k < 3; ++k) add(xyz[k], d.position[k], false);
    for (int k = 0; k < 4; ++k) add(rgba[k], d.color[k], false);
    add("size", d.size, false);
    add("instance", d.instance, false);
    return out;
}

// The drawn points copied out (any backend): id (n), position (n×3), color (n×4), size (n).
// On the CPU backends straight from the draw columns (what a NumPy copy of them costs,
// about); on the glsl backend read back through psys_read_points.
py::dict drawPoints(psys_system* s, size_t t) {
    size_t n = 0;
    psys_draw d;
    check(psys_get_draw(s, t, &d));
    bool onGpu = d.visible.gl_buffer || d.ids.gl_buffer || d.size.gl_buffer;
    for (const psys_column& c : d.position) onGpu |= c.gl_buffer != 0;
    for (const psys_column& c : d.color) onGpu |= c.gl_buffer != 0;
    auto value = [](const psys_column& c, size_t row) {
        return c.data ? static_cast<const float*>(c.data)[row] : c.constant;
    };
    std::vector<psys_point> read;
    if (onGpu) {
        check(psys_read_points(s, t, nullptr, 0, &n));
        read.resize(n);
        check(psys_read_points(s, t, read.data(), read.size(), &n));
    } else {
        for (size_t row = 0; row < d.rows; ++row) n += value(d.visible, row) == 1.0f;
    }
    auto rows = static_cast<py::ssize_t>(n);
    py::array_t<uint32_t> id(rows);
    py::array_t<float> position({rows, py::ssize_t{3}}), color({rows, py::ssize_t{4}}), size(rows);
    py::dict out;
    uint32_t* ids = id.mutable_data();
    float *xyz = position.mutable_data(), *rgba = color.mutable_data(), *sizes = size.mutable_data();
    if (onGpu) {
        for (size_t i = 0; i < n; ++i) {
            const psys_point& q = read[i];
            ids[i] = q.id;
            std::memcpy(xyz + 3 * i, q.position, sizeof q.position);
            std::memcpy(rgba + 4 * i, q.color, sizeof q.color);
            sizes[i] = q.size;
        }
    } else {
        const auto* idColumn = static_cast<const uint32_t*>(d.ids.data);
        for (size_t row = 0, i = 0; row < d.rows; ++row) {
            if (value(d.visible, row) != 1.0f) continue;
            ids[i] = idColumn ? idColumn[row] : static_cast<uint32_t>(d.ids.constant);
            for (int k = 0; k < 3; ++k) xyz[3 * i + static_cast<size_t>(k)] = value(d.position[k], row);
            for (int k = 0; k < 4; ++k) rgba[4 * i + static_cast<size_t>(k)] = value(d.color[k], row);
            sizes[i] = value(d.size, row);
            ++i;
        }
    }
    // Each point's instance (0 where the program is not instanced, and on the glsl
    // backend, which plays none).
    py::array_t<float> instance(rows);
    float* slots = instance.mutable_data();
    if (!onGpu && d.instance.data) {
        for (size_t row = 0, i = 0; row < d.rows; ++row)
            if (value(d.visible, row) == 1.0f) slots[i++] = value(d.instance, row);
    } else {
        std::fill(slots, slots + n, 0.0f);
    }
    out["instance"] = instance;
    out["id"] = id;
    out["position"] = position;
    out["color"] = color;
    out["size"] = size;
    return out;
}

// The drawn points' positions as an n×3 array (a copy: the columns are one a
// component), in row order; on the glsl backend read back as points() reads them.
py::array_t<float> drawPositions(psys_system* s, size_t t) {
    psys_draw d;
    check(psys_get_draw(s, t, &d));
    bool onGpu = d.visible.gl_buffer != 0;
    for (const psys_column& c : d.position) onGpu |= c.gl_buffer != 0;
    if (onGpu) return drawPoints(s, t)["position"].cast<py::array_t<float>>();
    auto column = [&](const psys_column& c, size_t row) {
        return c.data ? static_cast<const float*>(c.data)[row] : c.constant;
    };
    size_t n = 0;
    for (size_t row = 0; row < d.rows; ++row) n += column(d.visible, row) == 1.0f;
    py::array_t<float> out({static_cast<py::ssize_t>(n), py::ssize_t{3}});
    float* xyz = out.mutable_data();
    for (size_t row = 0; row < d.rows; ++row) {
        if (column(d.visible, row) != 1.0f) continue;
        for (int k = 0; k < 3; ++k) *xyz++ = column(d.position[k], row);
    }
    return out;
}

}  // namespace psys::python
