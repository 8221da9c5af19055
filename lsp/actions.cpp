// Edits the server offers: quick fixes (the fix-its the front end and the passes attach to
// their diagnostics: a did-you-mean, a missing standard-library import, an integrator or a
// step that keeps a decay stable) and formatting (frontend/format.h).
#include <optional>
#include <string_view>

#include <fmt/format.h>

#include "frontend/format.h"
#include "lsp/features.h"
#include "lsp/positions.h"

namespace psys::lsp {

nlohmann::json codeActions(const Analysis& a, uint32_t begin, uint32_t end) {
    nlohmann::json actions = nlohmann::json::array();
    for (const Diagnostic& d : a.diagnostics) {
        if (d.fixes.empty() || d.range.file != a.mainFile || d.range.end < begin || d.range.begin > end) continue;
        nlohmann::json diagnostic = diagnosticJson(a, d);
        for (size_t i = 0; i < d.fixes.size(); ++i) {
            const FixIt& fix = d.fixes[i];
            const SourceFile& f = a.sources->file(fix.range.file);
            nlohmann::json edit = {{"range", range(f, fix.range.begin, fix.range.end)}, {"newText", fix.replacement}};
            actions.push_back({{"title", fix.title},
                               {"kind", "quickfix"},
                               {"diagnostics", {diagnostic}},
                               {"isPreferred", i == 0},
                               {"edit", {{"changes", {{uriFromPath(f.path()), {edit}}}}}}});
        }
    }
    return actions;
}

namespace {

// The text laid out canonically, or why it cannot be.
std::optional<std::string> formatted(const std::string& path, const std::string& text, bool parses,
                                     const std::vector<LexedToken>* tokens, std::string& why) {
    SourceManager sources;
    DiagnosticEngine diags(sources);
    int file = sources.add(path, text);
    LayoutOptions layout;
    layout.parses = parses;
    layout.tokens = tokens;
    auto out = formatSource(file, sources, diags, layout);
    if (!out) {
        if (diags.all().empty()) why = "the file cannot be formatted";
        else {
            const Diagnostic& first = diags.all().front();
            LineColumn at = sources.file(file).lineColumn(first.range.begin);
            why = fmt::format("not formatted: fix the syntax first (line {}: {})", at.line, first.message);
        }
    }
    return out;
}

bool blank(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

}  // namespace

std::variant<nlohmann::json, std::string> rangeFormatting(const std::string& path, const std::string& text, uint32_t begin,
                                                          uint32_t end, bool parses,
                                                          const std::vector<LexedToken>* tokens) {
    std::string why;
    auto out = formatted(path, text, parses, tokens, why);
    if (!out) return why;
    // The layout changes only white space (frontend/format.h: the same tokens, comments
    // kept), so the two texts' other characters pair up one to one, and each run of white
    // space in the text is replaced by its partner in the layout: the runs that touch the
    // range are its edits, whatever the layout does elsewhere.
    SourceFile f(path, text);
    nlohmann::json edits = nlohmann::json::array();
    size_t i = 0, j = 0;
    for (;;) {
        size_t runStart = i, outStart = j;
        while (i < text.size() && blank(text[i])) ++i;
        while (j < out->size() && blank((*out)[j])) ++j;
        std::string_view was(text.data() + runStart, i - runStart), now(out->data() + outStart, j - outStart);
        if (was != now && runStart <= end && i >= begin)
            edits.push_back({{"range", range(f, static_cast<uint32_t>(runStart), static_cast<uint32_t>(i))},
                             {"newText", std::string(now)}});
        if (i == text.size() || j == out->size()) break;
        if (text[i] != (*out)[j]) return std::string("the layout changed more than white space: not formatted");
        ++i, ++j;
    }
    if (i != text.size() || j != out->size()) return std::string("the layout changed more than white space: not formatted");
    return edits;
}

std::variant<nlohmann::json, std::string> formatting(const std::string& path, const std::string& text, bool parses,
                                                     const std::vector<LexedToken>* tokens) {
    std::string why;
    auto out = formatted(path, text, parses, tokens, why);
    if (!out) return why;
    // One edit over what differs, not the whole text, so the editor keeps its cursor and marks.
    size_t prefix = 0, suffix = 0;
    while (prefix < text.size() && prefix < out->size() && text[prefix] == (*out)[prefix]) ++prefix;
    while (prefix > 0 && (static_cast<unsigned char>(text[prefix]) & 0xC0) == 0x80) --prefix;
    while (suffix < text.size() - prefix && suffix < out->size() - prefix &&
           text[text.size() - 1 - suffix] == (*out)[out->size() - 1 - suffix])
        ++suffix;
    while (suffix > 0 && (static_cast<unsigned char>(text[text.size() - suffix]) & 0xC0) == 0x80) --suffix;
    nlohmann::json edits = nlohmann::json::array();
    if (prefix == text.size() && prefix == out->size()) return edits;
    SourceFile f(path, text);
    edits.push_back({{"range", range(f, static_cast<uint32_t>(prefix), static_cast<uint32_t>(text.size() - suffix))},
                     {"newText", out->substr(prefix, out->size() - suffix - prefix)}});
    return edits;
}

}  // namespace psys::lsp
