// A window's mouse and keys, handed to the viewer: drag to orbit, right-drag or
// shift-drag to pan, the wheel to zoom, the keys of docs/viewer.md. What the panel is
// using (a slider being dragged, a field being typed in) is left to it.
#pragma once

struct GLFWwindow;

namespace psys::viewer {

class Viewer;

// Installs the window's callbacks (before the panel's, which chain to them).
void connectInput(GLFWwindow* window, Viewer& viewer);

}  // namespace psys::viewer
