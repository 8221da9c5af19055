// What a file with a syntax error and no earlier text that parsed still answers
// (lsp/salvage.cpp): its declarations but the broken ones.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace psys::lsp {

// The top-level declarations of `text` as byte ranges [begin, end), found by brackets,
// semicolons and declaration keywords at the start of a line (comments and strings skipped).
std::vector<std::pair<uint32_t, uint32_t>> topLevelDeclarations(const std::string& text);

// `text` with every top-level declaration that holds one of the `errors` (byte offsets;
// one at the end of the text counts for the last) blanked: spaces for all but line breaks.
// Nullopt where none does.
std::optional<std::string> blankBroken(const std::string& text, const std::vector<uint32_t>& errors);

}  // namespace psys::lsp
