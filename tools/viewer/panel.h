// The viewer's Dear ImGui panel: every extern as a control chosen by its type and range
// (a slider, three sliders, a colour picker, a checkbox) with a reset to its default,
// every trigger as a button with fields for its arguments, the time controls, the
// backend; the stats overlay; the diagnostics of an edit that does not compile.
#pragma once

#include <map>
#include <string>
#include <vector>

struct ImGuiContext;

namespace psys::viewer {

class Viewer;
class Surface;

class Panel {
public:
    Panel(Viewer& viewer, Surface& surface);
    ~Panel();
    Panel(const Panel&) = delete;
    Panel& operator=(const Panel&) = delete;

    // Builds this frame's panel and draws it over the frame.
    void draw();
    // The arguments entered for trigger `index` (keys 1–9 fire with them).
    std::vector<float> triggerArgs(size_t index) const;
    // Whether the panel has the mouse or the keyboard (the camera leaves them alone).
    bool wantsMouse() const;
    bool wantsKeyboard() const;
    // Whether the panel's font draws this character (not ImGui's "?" for it).
    bool hasGlyph(unsigned codepoint) const;

    bool visible = true;

private:
    void controls();
    void externs();
    void triggers();
    void stats();
    void diagnostics();
    void help();
    void typeVisibility(const std::string& name);

    Viewer& viewer_;
    Surface& surface_;
    ImGuiContext* context_ = nullptr;
    std::map<std::string, std::vector<float>> args_;  // per trigger
    int seed_ = 1;
};

}  // namespace psys::viewer
