// The orbit camera: it looks at a target from a distance, turned by yaw (about +y) and
// pitch (above the ground plane). Drag to orbit, right-drag or shift-drag to pan, the
// wheel to zoom; `frame` fits a box of points in view.
#pragma once

#include <optional>
#include <string>

#include <glm/glm.hpp>

namespace psys::viewer {

struct Camera {
    glm::vec3 target{0, 6, 0};
    float yaw = 0.6f;        // radians
    float pitch = 0.25f;     // radians, within (−π/2, π/2)
    float distance = 40;
    float fieldOfView = 0.8f;  // vertical, radians

    glm::vec3 eye() const;
    glm::mat4 view() const;
    glm::mat4 projection(float aspect) const;

    void orbit(float dxPixels, float dyPixels);
    void pan(float dxPixels, float dyPixels, float viewportHeight);
    void zoom(float steps);
    // Looks at the box [low, high] from the current direction, the box filling the view.
    void frame(glm::vec3 low, glm::vec3 high);
    void reset() { *this = Camera{}; }

    // "yaw,pitch,distance" or "yaw,pitch,distance,x,y,z" (angles in degrees).
    static std::optional<Camera> parse(const std::string& text);
};

}  // namespace psys::viewer
