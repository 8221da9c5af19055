// What a file with a syntax error still answers: the last analysis that parsed, its
// places moved into the text as it is now. The edits since are the runs of lines that
// differ between the two texts (a line diff), each narrowed to the characters that differ;
// what lies outside them is where it was (shifted by the edits before it), what lies
// inside one is not known and is left out. So one unfinished line costs hover, definition
// and symbols only on that line, however many other places changed since.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "lsp/analysis.h"

namespace psys::lsp {

// Offsets between an older text and the current one, through the edits between them.
class EditMap {
public:
    EditMap(const std::string& older, const std::string& current);
    // nullopt: inside an edit. At an insertion's place, an offset maps before what was
    // inserted, or after it where `after` (the start of a range that follows the insertion).
    std::optional<uint32_t> toOlder(uint32_t current, bool after = false) const;
    std::optional<uint32_t> toCurrent(uint32_t older, bool after = false) const;
    size_t edits() const { return hunks_.size(); }
    // An edit lies inside [begin, end) of the older text (not at its ends): what the range
    // held there is not what it holds now.
    bool touches(uint32_t begin, uint32_t end) const;

private:
    struct Hunk {
        uint32_t olderBegin, olderEnd, currentBegin, currentEnd;  // [begin, end) in each text
    };
    std::vector<Hunk> hunks_;  // in order, apart
    enum class Side { Older, Current };
    static std::pair<uint32_t, uint32_t> side(const Hunk& h, Side s) {
        return s == Side::Older ? std::pair(h.olderBegin, h.olderEnd) : std::pair(h.currentBegin, h.currentEnd);
    }
    std::optional<uint32_t> through(uint32_t at, bool after, Side from, Side to) const;
};

// `good`'s index (occurrences, symbols, scopes) over `text`, the main file's current text,
// with `current`'s diagnostics; Analysis::recovered is set. `readsOnly`: what the reads
// need (occurrences, symbols, hints), not the names completion and rename look up.
Analysis recover(const Analysis& good, const Analysis& current, const std::string& text, bool readsOnly = false);

// `a`'s outline moved through `edit` (from `a`'s main text): a symbol whose name an edit
// touched is left out, one with an edit inside it spans it.
std::vector<Symbol> movedSymbols(const Analysis& a, const EditMap& edit);

// The passes' warnings and hints of `passed` added to `fresh`, an analysis of a later text
// whose passes have not run (yet): each moved through the edits between the two texts, and
// dropped where an edit touched it (or, in an imported file, where that file changed).
// The editor keeps showing an unstable decay's warning while the passes run again.
void carryPasses(const Analysis& passed, Analysis& fresh);

}  // namespace psys::lsp
