// Drawing a frame's scene: a dark background with a faint ground grid and the axes (the
// objects: particles.h; the light and its glow: glow.h).
#pragma once

#include <epoxy/gl.h>

#include <glm/glm.hpp>

#include "rt/memory.h"
#include "rt/system.h"

namespace psys::viewer {

// The blending of the types whose program names none (@blend): the viewer's B switch.
enum class Blend { Additive, Alpha };

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
// A compute program from its source; throws std::runtime_error with the log.
GLuint linkComputeProgram(const char* source);

}  // namespace psys::viewer
