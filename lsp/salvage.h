// What a file with a syntax error and no earlier text that parsed still answers
// (lsp/salvage.cpp): its declarations but the broken ones.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace psys::lsp {

// (The declarations are frontend/parse_cache.h's topLevelDeclarations.)

// `text` with every top-level declaration that is unfinished or holds one of the `errors`
// (byte offsets; one at a declaration's end counts for it) blanked: spaces for all but
// line breaks.
// Nullopt where none does.
std::optional<std::string> blankBroken(const std::string& text, const std::vector<uint32_t>& errors);

}  // namespace psys::lsp
