// Back to front on the GPU: where a type's draw columns live in GL buffers (the GLSL
// backend), an alpha-blended sprite or streak type is sorted there, with nothing read
// back: a compute shader takes each row's depth in the eye's space, a bitonic sort orders
// (depth, row) pairs over the next power of two, and a gather writes each column in that
// order into buffers the draw then reads. The host only says how many rows there are.
#pragma once

#include <epoxy/gl.h>

#include <array>
#include <glm/glm.hpp>

namespace psys::viewer {

class DepthSort {
public:
    DepthSort();
    ~DepthSort();
    DepthSort(const DepthSort&) = delete;
    DepthSort& operator=(const DepthSort&) = delete;

    // Orders rows [0, rows) by depth, farthest first: `position` holds the GL buffers of
    // x, y, z (0: that component is `constant`'s), `visible` the visible column's (rows
    // not drawn go last).
    void order(GLuint visible, const std::array<GLuint, 3>& position, const glm::vec3& constant, size_t rows,
               const glm::mat4& view);
    // Writes `source`'s first `rows` floats in that order (where `sorted`; else as they
    // are) into `target`, row i at float i × stride + offset (a trail's points packed row
    // by row); a `source` of 0 writes `constant` for every row.
    void gather(GLuint source, GLuint target, size_t rows, bool sorted = true, size_t stride = 1, size_t offset = 0,
                float constant = 0);

private:
    void reserve(size_t padded);
    GLuint keys_ = 0, sort_ = 0, gather_ = 0;
    GLuint keyBuffer_ = 0, indexBuffer_ = 0;
    size_t capacity_ = 0;
};

}  // namespace psys::viewer
