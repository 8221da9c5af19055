// A file opened with a syntax error has no earlier text that parsed to answer from. Its
// top-level declarations are found by their brackets and semicolons, the ones that hold a
// syntax error are blanked (each of their characters but line breaks made a space, so
// every other offset is where it was) and the rest is analysed: outline, hover and
// definition then answer everywhere but in the broken declarations.
#include "lsp/salvage.h"

#include <cctype>
#include <string_view>

namespace psys::lsp {

namespace {

bool topKeyword(std::string_view text, size_t at) {
    for (std::string_view k : {"import", "const", "fn", "extern", "trigger", "object", "spawn"}) {
        if (text.compare(at, k.size(), k) != 0) continue;
        size_t end = at + k.size();
        if (end == text.size() || !(std::isalnum(static_cast<unsigned char>(text[end])) || text[end] == '_')) return true;
    }
    return false;
}

}  // namespace

std::vector<TopDeclaration> topLevelDeclarations(const std::string& text) {
    std::vector<TopDeclaration> out;
    size_t start = std::string::npos;
    int depth = 0;
    auto close = [&](size_t end, bool finished) {
        if (start != std::string::npos)
            out.push_back({static_cast<uint32_t>(start), static_cast<uint32_t>(end), !finished});
        start = std::string::npos;
        depth = 0;
    };
    for (size_t i = 0; i < text.size(); ++i) {
        char c = text[i];
        if (c == '/' && i + 1 < text.size() && text[i + 1] == '/') {  // comments are no declaration's
            while (i < text.size() && text[i] != '\n') ++i;
            continue;
        }
        if (c == '/' && i + 1 < text.size() && text[i + 1] == '*') {
            size_t end = text.find("*/", i + 2);
            i = end == std::string::npos ? text.size() : end + 1;
            continue;
        }
        if (std::isspace(static_cast<unsigned char>(c))) continue;
        // A declaration's keyword (or an attribute) at the start of a line begins a new
        // one, even where the one before is unfinished (a bracket left open, a missing
        // `;`): nested declarations are indented, so a missing `}` does not swallow the rest
        // of the file. (An object's attributes on the lines before it are its own.)
        bool lineStart = i == 0 || text[i - 1] == '\n';
        if (lineStart && (c == '@' || topKeyword(text, i)) && start != std::string::npos &&
            (depth > 0 || text[start] != '@'))
            close(i, false);
        if (start == std::string::npos) start = i;
        if (c == '"') {
            for (++i; i < text.size() && text[i] != '"' && text[i] != '\n'; ++i)
                if (text[i] == '\\') ++i;
            continue;
        }
        if (c == '{' || c == '(') ++depth;
        else if ((c == '}' || c == ')') && depth > 0) {
            if (--depth == 0 && c == '}') close(i + 1, true);
        } else if (c == ';' && depth == 0) {
            close(i + 1, true);
        }
    }
    close(text.size(), false);
    return out;
}

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
