#include "lsp/features.h"

#include <fmt/format.h>

#include "lsp/positions.h"

namespace psys::lsp {

namespace {

nlohmann::json location(const SourceManager& sources, SourceRange r) {
    const SourceFile& f = sources.file(r.file);
    return {{"uri", uriFromPath(f.path())}, {"range", range(f, r.begin, r.end)}};
}

}  // namespace

nlohmann::json diagnosticJson(const Analysis& a, const Diagnostic& d) {
    SourceRange r = d.range.valid() ? d.range : SourceRange{a.mainFile, 0, 0};
    const SourceFile& f = a.sources->file(r.file);
    nlohmann::json related = nlohmann::json::array();
    for (const DiagnosticNote& n : d.notes)
        if (n.range.valid()) related.push_back({{"location", location(*a.sources, n.range)}, {"message", n.message}});
    std::string message = d.message;
    for (const DiagnosticNote& n : d.notes)
        if (!n.range.valid()) message += "\nnote: " + n.message;
    nlohmann::json diag = {{"range", range(f, r.begin, r.end)},
                           {"severity", d.severity == Severity::Error ? 1 : d.severity == Severity::Warning ? 2 : 3},
                           {"source", "psysc"},
                           {"message", message}};
    if (!related.empty()) diag["relatedInformation"] = related;
    return diag;
}

std::map<std::string, nlohmann::json> diagnosticsByUri(const Analysis& a) {
    std::map<std::string, nlohmann::json> out;
    if (a.mainFile >= 0) out[uriFromPath(a.sources->file(a.mainFile).path())] = nlohmann::json::array();
    for (const Diagnostic& d : a.diagnostics) {
        // A diagnostic without a place (a file that cannot be read) goes to the top of the main file.
        SourceRange r = d.range.valid() ? d.range : SourceRange{a.mainFile, 0, 0};
        if (r.file < 0) continue;
        const SourceFile& f = a.sources->file(r.file);
        out[uriFromPath(f.path())].push_back(diagnosticJson(a, d));
        // An error in an imported file also shows at the main file's import that brings
        // it in (the file that has it may not be open): `psysc check` of the main file fails.
        if (d.severity == Severity::Error && r.file != a.mainFile) {
            SourceRange at = r;
            while (at.valid() && at.file != a.mainFile) at = a.sources->importedAt(at.file);
            if (!at.valid()) continue;
            const SourceFile& main = a.sources->file(a.mainFile);
            LineColumn lc = f.lineColumn(r.begin);
            nlohmann::json shown = {{"range", range(main, at.begin, at.end)},
                                    {"severity", 1},
                                    {"source", "psysc"},
                                    {"message", fmt::format("an error in {}:{}:{}: {}", f.path(), lc.line, lc.column, d.message)},
                                    {"relatedInformation", {{{"location", location(*a.sources, r)}, {"message", d.message}}}}};
            out[uriFromPath(main.path())].push_back(shown);
        }
    }
    if ((a.hiddenErrors > 0 || a.hiddenWarnings > 0) && a.mainFile >= 0) {
        const SourceFile& main = a.sources->file(a.mainFile);
        out[uriFromPath(main.path())].push_back(
            {{"range", range(main, 0, 0)},
             {"severity", a.hiddenErrors > 0 ? 1 : 2},
             {"source", "psysc"},
             {"message", fmt::format("{} more errors and {} more warnings are not listed (the first {} of each are)",
                                     a.hiddenErrors, a.hiddenWarnings, kMaxPublished)}});
    }
    return out;
}

nlohmann::json hover(const Analysis& a, uint32_t offset) {
    const Occurrence* o = a.parsed ? a.at(a.mainFile, offset) : nullptr;
    if (!o || !o->hover || o->hover->empty()) return nullptr;
    const SourceFile& f = a.sources->file(a.mainFile);
    return {{"contents", {{"kind", "markdown"}, {"value", *o->hover}}}, {"range", range(f, o->range.begin, o->range.end)}};
}

nlohmann::json definition(const Analysis& a, uint32_t offset) {
    const Occurrence* o = a.parsed ? a.at(a.mainFile, offset) : nullptr;
    if (!o || !o->definition || !o->definition->valid()) return nullptr;
    return location(*a.sources, *o->definition);
}

namespace {

// JSON text written directly: 20,000 lines have 15,000 symbols, and a tree of them in
// nlohmann's objects takes longer to build, write out and free than the analysis that
// found them. Keys in the order nlohmann writes them (sorted), so the text is the one
// a tree would give.
void jsonString(fmt::memory_buffer& out, const std::string& s) {
    out.push_back('"');
    for (char c : s) {
        if (c == '"' || c == '\\') {
            out.push_back('\\');
            out.push_back(c);
        } else if (c == '\n' || c == '\t' || c == '\r' || c == '\b' || c == '\f') {
            out.push_back('\\');
            out.push_back(c == '\n' ? 'n' : c == '\t' ? 't' : c == '\r' ? 'r' : c == '\b' ? 'b' : 'f');
        } else if (static_cast<unsigned char>(c) < 0x20) {
            fmt::format_to(std::back_inserter(out), "\\u{:04x}", static_cast<unsigned char>(c));
        } else {
            out.push_back(c);
        }
    }
    out.push_back('"');
}

void jsonRange(fmt::memory_buffer& out, const SourceFile& f, SourceRange r) {
    LineCharacter b = lineCharacter(f, r.begin), e = lineCharacter(f, r.end);
    fmt::format_to(std::back_inserter(out), R"({{"end":{{"character":{},"line":{}}},"start":{{"character":{},"line":{}}}}})",
                   e.character, e.line, b.character, b.line);
}

void symbolJson(fmt::memory_buffer& out, const SourceFile& f, const Symbol& s) {
    fmt::format_to(std::back_inserter(out), R"({{"children":[)");
    for (size_t i = 0; i < s.children.size(); ++i) {
        if (i) out.push_back(',');
        symbolJson(out, f, s.children[i]);
    }
    fmt::format_to(std::back_inserter(out), "],");
    if (!s.detail.empty()) {
        fmt::format_to(std::back_inserter(out), R"("detail":)");
        jsonString(out, s.detail);
        out.push_back(',');
    }
    fmt::format_to(std::back_inserter(out), R"("kind":{},"name":)", static_cast<int>(s.kind));
    jsonString(out, s.name);
    fmt::format_to(std::back_inserter(out), R"(,"range":)");
    jsonRange(out, f, s.range);
    fmt::format_to(std::back_inserter(out), R"(,"selectionRange":)");
    jsonRange(out, f, s.selection);
    out.push_back('}');
}

}  // namespace

nlohmann::json inlayHints(const Analysis& a, uint32_t begin, uint32_t end) {
    nlohmann::json out = nlohmann::json::array();
    if (!a.parsed) return out;
    const SourceFile& f = a.sources->file(a.mainFile);
    for (const Hint& h : a.hints) {
        if (h.at.file != a.mainFile || h.at.end < begin || h.at.end > end) continue;
        out.push_back({{"position", position(f, h.at.end)}, {"label", h.label}, {"kind", h.kind}, {"paddingLeft", h.kind == 2}});
    }
    return out;
}

std::string documentSymbols(const SourceFile& file, const std::vector<Symbol>& symbols) {
    fmt::memory_buffer out;
    out.push_back('[');
    for (size_t i = 0; i < symbols.size(); ++i) {
        if (i) out.push_back(',');
        symbolJson(out, file, symbols[i]);
    }
    out.push_back(']');
    return fmt::to_string(out);
}

std::string documentSymbols(const Analysis& a) {
    if (!a.parsed) return "[]";
    return documentSymbols(a.sources->file(a.mainFile), a.symbols);
}

}  // namespace psys::lsp
