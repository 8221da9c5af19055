// What a file with a syntax error still answers: the last analysis that parsed, its
// places moved into the text as it is now. The edit since is the span between the two
// texts' common prefix and common suffix; what lies outside it is where it was (shifted
// by the edit's length after it), what lies inside it is not known and is left out. So
// one unfinished line costs hover, definition and symbols only on that line.
#pragma once

#include <optional>
#include <string>

#include "lsp/analysis.h"

namespace psys::lsp {

// Offsets between an older text and the current one, through the edit between them.
class EditMap {
public:
    EditMap(const std::string& older, const std::string& current);
    std::optional<uint32_t> toOlder(uint32_t current) const;  // nullopt: inside the edit
    std::optional<uint32_t> toCurrent(uint32_t older) const;  // nullopt: inside what the edit replaced

private:
    uint32_t prefix_ = 0, suffix_ = 0, olderSize_ = 0, currentSize_ = 0;
};

// `good`'s index (occurrences, symbols, scopes) over `text`, the main file's current text,
// with `current`'s diagnostics; Analysis::recovered is set.
Analysis recover(const Analysis& good, const Analysis& current, const std::string& text);

}  // namespace psys::lsp
