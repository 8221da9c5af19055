// Drawing a frame: the points of every type straight from the run-time's draw columns
// (rt::DrawColumns: uploaded column by column, never a per-point structure), as round,
// soft-edged sprites sized by `size` (pixels at the reference distance, smaller with
// depth), over a dark background with a faint ground grid and the axes.
#pragma once

#include <epoxy/gl.h>

#include <glm/glm.hpp>

#include "rt/memory.h"
#include "rt/system.h"

namespace psys::viewer {

enum class Blend { Additive, Alpha };

// A point's `size` is its diameter in pixels seen from this distance (on a 720-pixel-high
// view; scaled with the view's height).
constexpr float kReferenceDistance = 20;

class PointRenderer {
public:
    PointRenderer();
    ~PointRenderer();
    PointRenderer(const PointRenderer&) = delete;
    PointRenderer& operator=(const PointRenderer&) = delete;
    void draw(const rt::DrawColumns& columns, const rt::Memory& memory, const glm::mat4& view,
              const glm::mat4& projection, float viewportHeight, Blend blend);

private:
    static constexpr int kColumns = 9;  // visible, x, y, z, r, g, b, a, size
    GLuint program_ = 0, vao_ = 0, buffers_[kColumns] = {};
    size_t capacity_[kColumns] = {};
    std::vector<float> staging_;
};

class SceneRenderer {
public:
    SceneRenderer();
    ~SceneRenderer();
    SceneRenderer(const SceneRenderer&) = delete;
    SceneRenderer& operator=(const SceneRenderer&) = delete;
    // The ground grid (y = 0) and the axes (x red, y green, z blue), when `grid`.
    void draw(const glm::mat4& view, const glm::mat4& projection, bool grid);

private:
    GLuint program_ = 0, vao_ = 0, buffer_ = 0;
    GLsizei gridVertices_ = 0, axisVertices_ = 0;
};

// Clears to the background colour.
void clearFrame();

// A program from two shader sources; throws std::runtime_error with the log.
GLuint linkProgram(const char* vertex, const char* fragment);

}  // namespace psys::viewer
