// Scripted input: what a person would do, at given frames — for tests of the window path
// and for reproducible screenshots. One action a line:
//
//   FRAME orbit DX DY      drag to orbit, in pixels
//   FRAME pan DX DY        right-drag to pan
//   FRAME zoom STEPS       the wheel (positive: closer)
//   FRAME key K            a key: F R B G H SPACE S 1…9 (docs/viewer.md)
//   FRAME set NAME=V,…     an extern, as the panel sets it
//   FRAME fire T[:A,…]     a trigger, as its button fires it
//   FRAME screenshot PATH  a PNG of that frame
//   FRAME quit
//
// `#` starts a comment. Actions run before the frame's step, in file order.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace psys::viewer {

struct ScriptAction {
    int frame = 0;
    std::string verb;
    std::vector<std::string> words;
};

struct Script {
    std::vector<ScriptAction> actions;
    // Parses a script; on a bad line, nullopt and `error` says which and why.
    static std::optional<Script> parse(const std::string& text, std::string& error);
};

}  // namespace psys::viewer
