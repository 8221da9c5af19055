// Scripted input: what a person would do, at given frames — for tests of the window path
// and for reproducible screenshots. One action a line:
//
//   FRAME orbit DX DY      drag to orbit, in pixels
//   FRAME pan DX DY        right-drag to pan
//   FRAME zoom STEPS       the wheel (positive: closer)
//   FRAME key K            a key: F R B G H SPACE S T = - P V F1 ? 1…9 … (keys.h)
//   FRAME set NAME=V,…     an extern, as the panel sets it
//   FRAME fire T[:A,…]     a trigger, as its button fires it
//   FRAME screenshot PATH  an image of that frame, once drawn (.png, .jpg, .bmp, .tga)
//   FRAME quit
//
// `#` starts a comment. Actions run before the frame's step, in file order (a screenshot
// is taken when the frame has been drawn). The whole
// script is checked when it is read — frame numbers, numbers (finite), keys, the form of
// settings and firings, image formats — and a bad line is named FILE:LINE.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace psys::viewer {

struct ScriptAction {
    int frame = 0;
    std::string verb;
    std::vector<std::string> words;
    std::vector<float> numbers;  // orbit, pan, zoom: the words as numbers
};

struct Script {
    std::vector<ScriptAction> actions;
    // Parses a script read from `file`; on a bad line, nullopt and `error` says
    // "FILE:LINE: why".
    static std::optional<Script> parse(const std::string& text, const std::string& file, std::string& error);
};

}  // namespace psys::viewer
