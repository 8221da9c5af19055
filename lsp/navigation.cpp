// Moving around a file: an import's path as a link to the file it loads, selection ranges
// that grow from the name at the cursor through its expressions and declarations to the
// whole file, and the file's diagnostics when the editor asks for them (pull diagnostics).
#include <algorithm>

#include "frontend/builtins.h"
#include "lsp/features.h"
#include "lsp/positions.h"

namespace psys::lsp {

using nlohmann::json;

json documentLinks(const Analysis& a) {
    json links = json::array();
    if (!a.parsed) return links;
    // An import's path is the one occurrence whose definition is a whole other file (an
    // empty range at its start: lsp/index_builder.cpp).
    const SourceFile& main = a.sources->file(a.mainFile);
    for (const Occurrence& o : a.occurrences) {
        if (o.range.file != a.mainFile || !o.definition || o.definition->file == a.mainFile) continue;
        if (o.definition->begin != 0 || o.definition->end != 0 || !o.definition->valid()) continue;
        const std::string& target = a.sources->file(o.definition->file).path();
        links.push_back({{"range", range(main, o.range.begin, o.range.end)},
                         {"target", uriFromPath(target)},
                         {"tooltip", target}});
    }
    return links;
}

namespace {

void symbolRanges(const std::vector<Symbol>& symbols, uint32_t offset, std::vector<std::pair<uint32_t, uint32_t>>& out) {
    for (const Symbol& s : symbols) {
        if (s.range.begin > offset || offset > s.range.end) continue;
        out.push_back({s.range.begin, s.range.end});
        if (s.selection.begin <= offset && offset <= s.selection.end) out.push_back({s.selection.begin, s.selection.end});
        symbolRanges(s.children, offset, out);
    }
}

}  // namespace

json selectionRange(const Analysis& a, uint32_t offset) {
    const SourceFile& f = a.sources->file(a.mainFile);
    auto size = static_cast<uint32_t>(f.text().size());
    // Every range around the cursor: the names and expressions, the declarations and their
    // names, the file. Each one the editor grows to holds the one before.
    std::vector<std::pair<uint32_t, uint32_t>> around = {{0, size}};
    if (a.parsed) {
        for (const Occurrence& o : a.occurrences)
            if (o.range.file == a.mainFile && o.range.begin <= offset && offset <= o.range.end) around.push_back({o.range.begin, o.range.end});
        symbolRanges(a.symbols, offset, around);
    }
    std::sort(around.begin(), around.end(), [](auto x, auto y) {
        return x.second - x.first != y.second - y.first ? x.second - x.first < y.second - y.first : x.first < y.first;
    });
    std::vector<std::pair<uint32_t, uint32_t>> chain;
    for (auto r : around)
        if (chain.empty() || (r.first <= chain.back().first && chain.back().second <= r.second && r != chain.back()))
            chain.push_back(r);
    json selection = nullptr;
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
        json next = {{"range", range(f, it->first, it->second)}};
        if (!selection.is_null()) next["parent"] = std::move(selection);
        selection = std::move(next);
    }
    return selection;
}

json documentDiagnostics(const Analysis& a) {
    std::map<std::string, json> byUri = diagnosticsByUri(a);
    std::string main = uriFromPath(a.sources->file(a.mainFile).path());
    return {{"kind", "full"}, {"items", byUri[main]}};
}

json resolveCompletion(json item) {
    // Items are complete when listed, but for the built-ins' longer texts, which are added
    // to the one item the editor shows in full.
    if (!item.is_object() || !item.contains("label") || !item["label"].is_string() || item.contains("documentation"))
        return item;
    // Which word it is, by the kind (and detail) completion gave it: a user's `const rk4`
    // is not the integrator.
    std::string label = item["label"];
    int kind = item.contains("kind") && item["kind"].is_number_integer() ? item["kind"].get<int>() : 0;
    std::string detail = item.contains("detail") && item["detail"].is_string() ? item["detail"].get<std::string>() : "";
    std::string doc;
    if (kind == static_cast<int>(CompletionKind::Keyword)) doc = std::string(commandDoc(label));
    else if (kind == static_cast<int>(CompletionKind::TypeParameter)) doc = std::string(typeDoc(label));
    else if (kind == static_cast<int>(CompletionKind::Property) && detail.starts_with("@")) doc = std::string(attributeDoc(label));
    else if (kind == static_cast<int>(CompletionKind::Constant) && detail == "integrator") doc = integratorDoc(label);
    if (!doc.empty()) item["documentation"] = {{"kind", "markdown"}, {"value", doc}};
    return item;
}

}  // namespace psys::lsp
