// A file opened with a syntax error has no earlier text that parsed to answer from. Its
// top-level declarations are found by their brackets and semicolons, the ones that hold a
// syntax error are blanked (each of their characters but line breaks made a space, so
// every other offset is where it was) and the rest is analysed: outline, hover and
// definition then answer everywhere but in the broken declarations.
#include "lsp/salvage.h"

#include "frontend/parse_cache.h"

namespace psys::lsp {

std::optional<std::string> blankBroken(const std::string& text, const std::vector<uint32_t>& errors) {
    std::string out = text;
    bool blanked = false;
    for (auto [begin, end, unfinished] : topLevelDeclarations(text)) {
        // (A missing `}` is reported where the parser gave up, maybe in the next
        // declaration: the one left open is blanked whatever the errors say.)
        bool broken = unfinished;
        for (uint32_t e : errors) broken |= begin <= e && e <= end;
        if (!broken) continue;
        for (uint32_t i = begin; i < end; ++i)
            if (out[i] != '\n') out[i] = ' ';
        blanked = true;
    }
    if (!blanked) return std::nullopt;
    return out;
}

}  // namespace psys::lsp
