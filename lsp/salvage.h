// What a file with a syntax error and no earlier text that parsed still answers
// (lsp/salvage.cpp): its declarations but the broken ones.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace psys::lsp {

struct TopDeclaration {
    uint32_t begin, end;  // [begin, end) of the text
    bool unfinished;      // cut off (by the next declaration's keyword, or the end) before its `;` or `}`
};

// The top-level declarations of `text`, found by brackets, semicolons and declaration
// keywords at the start of a line (comments and strings skipped).
std::vector<TopDeclaration> topLevelDeclarations(const std::string& text);

// `text` with every top-level declaration that is unfinished or holds one of the `errors`
// (byte offsets; one at a declaration's end counts for it) blanked: spaces for all but
// line breaks.
// Nullopt where none does.
std::optional<std::string> blankBroken(const std::string& text, const std::vector<uint32_t>& errors);

}  // namespace psys::lsp
