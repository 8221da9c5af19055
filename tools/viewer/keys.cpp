#include "keys.h"

#include <algorithm>

#include <GLFW/glfw3.h>
#include <fmt/format.h>

namespace psys::viewer {

const std::vector<KeyBinding>& keyBindings() {
    static const std::vector<KeyBinding> table = [] {
        std::vector<KeyBinding> t = {
            {"drag", "orbit around the target", {}},
            {"right-drag, shift-drag", "pan", {}},
            {"wheel", "zoom", {}},
            {"F", "frame what is alive (the box of the drawn points, without the farthest 2% on each side)",
             {{"F", GLFW_KEY_F}}},
            {"R", "reset the camera", {{"R", GLFW_KEY_R}}},
            {"B", "additive or alpha blending, for types whose program names no @blend", {{"B", GLFW_KEY_B}}},
            {"G", "the ground grid and axes", {{"G", GLFW_KEY_G}}},
            {"L", "the glow (and tone mapping) of bright light", {{"L", GLFW_KEY_L}}},
            {"H", "hide the panel and the stats", {{"H", GLFW_KEY_H}}},
            {"Space", "pause", {{"SPACE", GLFW_KEY_SPACE}}},
            {"S", "one step (while paused)", {{"S", GLFW_KEY_S}}},
            {"T", "real time, or a fixed step a frame", {{"T", GLFW_KEY_T}}},
            {"+, -", "time scale ×2, ÷2", {{"=", GLFW_KEY_EQUAL}, {"-", GLFW_KEY_MINUS}}},
            {"1–9", "fire trigger 1–9 with the arguments in the panel", {}},
            {"P", "a screenshot: FILE's name and a number, .png, in the current folder", {{"P", GLFW_KEY_P}}},
            {"V", "start or stop recording a clip (.mp4 where ffmpeg is on the PATH, else a folder of PNGs)",
             {{"V", GLFW_KEY_V}}},
            {"F1, ?", "this help", {{"F1", GLFW_KEY_F1}, {"?", GLFW_KEY_SLASH, true}}},
            {"Q, Esc", "quit", {{"Q", GLFW_KEY_Q}, {"ESC", GLFW_KEY_ESCAPE}}},
        };
        auto& triggers = std::find_if(t.begin(), t.end(), [](const KeyBinding& b) { return b.keys == "1–9"; })->presses;
        for (int n = 1; n <= 9; ++n) triggers.push_back({std::to_string(n), GLFW_KEY_0 + n});
        return t;
    }();
    return table;
}

std::optional<KeyPress> keyPress(const std::string& name) {
    for (const KeyBinding& b : keyBindings())
        for (const KeyPress& p : b.presses)
            if (p.name == name) return p;
    return std::nullopt;
}

std::string keyNames() {
    std::string out;
    for (const KeyBinding& b : keyBindings()) {
        if (b.keys == "1–9") {
            out += " 1…9";
            continue;
        }
        for (const KeyPress& p : b.presses) out += " " + p.name;
    }
    return out.substr(1);
}

std::string keysMarkdown() {
    std::string out = "| input | does |\n|---|---|\n";
    for (const KeyBinding& b : keyBindings()) {
        std::string keys;
        bool mouse = b.presses.empty() && b.keys != "1–9";
        // Keys in code spans; the mouse's words, and the digits' range, as they are.
        if (mouse || b.keys == "1–9") keys = mouse ? b.keys : "`1`–`9`";
        else {
            size_t at = 0;
            while (at < b.keys.size()) {
                size_t comma = b.keys.find(", ", at);
                std::string k = b.keys.substr(at, comma == std::string::npos ? std::string::npos : comma - at);
                keys += (keys.empty() ? "" : ", ") + ("`" + k + "`");
                at = comma == std::string::npos ? b.keys.size() : comma + 2;
            }
        }
        out += "| " + keys + " | " + b.does + " |\n";
    }
    return out;
}

std::string keysText() {
    std::string out;
    for (const KeyBinding& b : keyBindings()) out += fmt::format("  {:<24}{}\n", b.keys, b.does);
    return out;
}

}  // namespace psys::viewer
