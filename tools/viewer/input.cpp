#include "input.h"

#include <GLFW/glfw3.h>
#include <imgui.h>

#include "viewer.h"

namespace psys::viewer {

namespace {

struct Input {
    Viewer* viewer = nullptr;
    bool orbiting = false, panning = false;
    double x = 0, y = 0;
};

Input input;

bool panelHas(bool mouse) {
    if (!ImGui::GetCurrentContext()) return false;
    return mouse ? ImGui::GetIO().WantCaptureMouse : ImGui::GetIO().WantCaptureKeyboard;
}

void onKey(GLFWwindow*, int key, int, int action, int mods) {
    if (action != GLFW_PRESS || panelHas(false)) return;
    input.viewer->key(key, (mods & GLFW_MOD_SHIFT) != 0);
}

void onButton(GLFWwindow* window, int button, int action, int mods) {
    bool press = action == GLFW_PRESS;
    if (press && panelHas(true)) return;
    glfwGetCursorPos(window, &input.x, &input.y);
    bool shift = (mods & GLFW_MOD_SHIFT) != 0;
    if (button == GLFW_MOUSE_BUTTON_LEFT) {
        input.orbiting = press && !shift;
        input.panning = press && shift;
    }
    if (button == GLFW_MOUSE_BUTTON_RIGHT || button == GLFW_MOUSE_BUTTON_MIDDLE) input.panning = press;
}

void onMove(GLFWwindow*, double x, double y) {
    auto dx = static_cast<float>(x - input.x), dy = static_cast<float>(y - input.y);
    input.x = x;
    input.y = y;
    if (input.orbiting) input.viewer->orbit(dx, dy);
    if (input.panning) input.viewer->pan(dx, dy);
}

void onScroll(GLFWwindow*, double, double dy) {
    if (panelHas(true)) return;
    input.viewer->zoom(static_cast<float>(dy));
}

}  // namespace

void connectInput(GLFWwindow* window, Viewer& viewer) {
    input.viewer = &viewer;
    glfwSetKeyCallback(window, onKey);
    glfwSetMouseButtonCallback(window, onButton);
    glfwSetCursorPosCallback(window, onMove);
    glfwSetScrollCallback(window, onScroll);
}

}  // namespace psys::viewer
