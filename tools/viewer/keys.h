// The viewer's keys, written once: what `psys-view --help` and `--keys` print, what the
// help overlay (F1 or ?) shows, the names a script's `key` action takes, and the table in
// docs/viewer.md (a test compares it with `psys-view --keys`). Viewer::key does what
// each says.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace psys::viewer {

struct KeyPress {
    std::string name;  // in a script: `key NAME`
    int code;          // GLFW_KEY_…
    bool shift = false;
};

struct KeyBinding {
    std::string keys;  // as a person reads them: "F", "1–9", "Q, Esc"
    std::string does;
    std::vector<KeyPress> presses;
};

const std::vector<KeyBinding>& keyBindings();
// The press a script's key name stands for.
std::optional<KeyPress> keyPress(const std::string& name);
std::string keyNames();       // "F R B … SPACE 1…9": for an error about an unknown key
std::string keysMarkdown();   // the table of docs/viewer.md
std::string keysText();       // the same for a terminal (--help)

}  // namespace psys::viewer
