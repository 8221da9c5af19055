#include "camera.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

namespace psys::viewer {

glm::vec3 Camera::eye() const {
    glm::vec3 direction{std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw)};
    return target + direction * distance;
}

glm::mat4 Camera::view() const { return glm::lookAt(eye(), target, glm::vec3(0, 1, 0)); }

glm::mat4 Camera::projection(float aspect) const {
    float near = std::max(0.01f, distance * 0.001f), far = distance * 100 + 1000;
    return glm::perspective(fieldOfView, aspect, near, far);
}

void Camera::orbit(float dx, float dy) {
    yaw -= dx * 0.005f;
    pitch = std::clamp(pitch + dy * 0.005f, -1.55f, 1.55f);
}

void Camera::pan(float dx, float dy, float viewportHeight) {
    // A pixel's size at the target's depth.
    float unit = 2 * distance * std::tan(fieldOfView / 2) / std::max(viewportHeight, 1.0f);
    glm::mat4 v = view();
    glm::vec3 right{v[0][0], v[1][0], v[2][0]}, up{v[0][1], v[1][1], v[2][1]};
    target += (-dx * right + dy * up) * unit;
}

void Camera::zoom(float steps) { distance = std::clamp(distance * std::pow(0.88f, steps), 0.05f, 1e5f); }

void Camera::frame(glm::vec3 low, glm::vec3 high) {
    target = (low + high) * 0.5f;
    float radius = std::max(glm::length(high - low) * 0.5f, 0.5f);
    distance = radius / std::sin(fieldOfView / 2) * 1.1f;
}

std::optional<Camera> Camera::parse(const std::string& text) {
    if (text.empty() || text.back() == ',') return std::nullopt;  // (getline drops a last empty item)
    std::vector<float> v;
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) {
        char* end = nullptr;
        float x = std::strtof(item.c_str(), &end);
        if (item.empty() || *end != '\0' || !std::isfinite(x)) return std::nullopt;
        v.push_back(x);
    }
    if (v.size() != 3 && v.size() != 6) return std::nullopt;
    Camera c;
    c.yaw = glm::radians(v[0]);
    c.pitch = std::clamp(glm::radians(v[1]), -1.55f, 1.55f);
    c.distance = std::max(v[2], 0.05f);
    if (v.size() == 6) c.target = {v[3], v[4], v[5]};
    return c;
}

}  // namespace psys::viewer
