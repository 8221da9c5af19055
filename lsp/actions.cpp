// Edits the server offers: quick fixes (the fix-its the front end and the passes attach to
// their diagnostics: a did-you-mean, a missing standard-library import, an integrator or a
// step that keeps a decay stable) and formatting (frontend/format.h).
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

std::variant<nlohmann::json, std::string> formatting(const std::string& path, const std::string& text) {
    SourceManager sources;
    DiagnosticEngine diags(sources);
    int file = sources.add(path, text);
    auto out = formatSource(file, sources, diags);
    if (!out) {
        if (diags.all().empty()) return std::string("the file cannot be formatted");
        const Diagnostic& first = diags.all().front();
        LineColumn at = sources.file(file).lineColumn(first.range.begin);
        return fmt::format("not formatted: fix the syntax first (line {}: {})", at.line, first.message);
    }
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
    const SourceFile& f = sources.file(file);
    edits.push_back({{"range", range(f, static_cast<uint32_t>(prefix), static_cast<uint32_t>(text.size() - suffix))},
                     {"newText", out->substr(prefix, out->size() - suffix - prefix)}});
    return edits;
}

}  // namespace psys::lsp
