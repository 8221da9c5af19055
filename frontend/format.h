// The canonical layout of a .psys file: what `psysc fmt` prints and the language server's
// formatting applies. The rules are in docs/language.md (§ Layout).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "frontend/diagnostics.h"
#include "frontend/parse.h"

namespace psys {

// The file laid out canonically, its comments kept where they were. Nullopt when it has
// syntax errors (reported to `diags`: a file is formatted only when its every token is
// known). The result has the same tokens in the same order, so the same meaning; the
// formatter checks that before it answers, and formatting it again changes nothing.
struct LayoutOptions {
    // A line longer than this (its indentation counted) is broken after a comma or a binary
    // operator, at the shallowest bracket depth that fits, the rest indented one level past
    // the line of the innermost bracket still open; 0: lines are never broken.
    int width = 100;
    // The caller knows the text parses (an editor that has just analysed it), so it is not
    // parsed again here (it is still lexed; and once more, the check of the tokens, where
    // the layout changes it).
    bool parses = false;
    // The text's tokens where the caller has them (the language server's parse cache,
    // frontend/parse_cache.h): the text parses, and is not lexed again.
    const std::vector<LexedToken>* tokens = nullptr;
};

std::optional<std::string> formatSource(int file, const SourceManager& sources, DiagnosticEngine& diags,
                                        const LayoutOptions& options = {});

}  // namespace psys
