#include "lsp/recover.h"

#include <algorithm>

namespace psys::lsp {

EditMap::EditMap(const std::string& older, const std::string& current)
    : olderSize_(static_cast<uint32_t>(older.size())), currentSize_(static_cast<uint32_t>(current.size())) {
    uint32_t shorter = std::min(olderSize_, currentSize_);
    while (prefix_ < shorter && older[prefix_] == current[prefix_]) ++prefix_;
    while (suffix_ < shorter - prefix_ && older[olderSize_ - 1 - suffix_] == current[currentSize_ - 1 - suffix_])
        ++suffix_;
}

std::optional<uint32_t> EditMap::toOlder(uint32_t current) const {
    if (current <= prefix_) return current;
    if (current >= currentSize_ - suffix_) return current - currentSize_ + olderSize_;
    return std::nullopt;
}

std::optional<uint32_t> EditMap::toCurrent(uint32_t older) const {
    if (older <= prefix_) return older;
    if (older >= olderSize_ - suffix_) return older - olderSize_ + currentSize_;
    return std::nullopt;
}

namespace {

struct Mover {
    const EditMap& edit;
    int main;

    // A place in the main file moved, or nullopt where the edit touched it; other files' as they are.
    std::optional<SourceRange> strict(SourceRange r) const {
        if (r.file != main) return r;
        auto b = edit.toCurrent(r.begin), e = edit.toCurrent(r.end);
        if (!b || !e) return std::nullopt;
        return SourceRange{r.file, *b, *e};
    }
    // A declaration's whole range: where the edit is inside it, it still spans the edit.
    std::optional<SourceRange> spanning(SourceRange r) const {
        if (r.file != main) return r;
        auto b = edit.toCurrent(r.begin), e = edit.toCurrent(r.end);
        if (!b || !e) return std::nullopt;
        return SourceRange{r.file, *b, std::max(*b, *e)};
    }

    bool symbol(Symbol& s) const {
        auto range = spanning(s.range), selection = strict(s.selection);
        if (!range || !selection) return false;
        s.range = *range;
        s.selection = *selection;
        std::vector<Symbol> kept;
        for (Symbol& c : s.children)
            if (symbol(c)) kept.push_back(std::move(c));
        s.children = std::move(kept);
        return true;
    }
};

}  // namespace

Analysis recover(const Analysis& good, const Analysis& current, const std::string& text) {
    Analysis out;
    out.sources = std::make_unique<SourceManager>();
    for (int f = 0; f < good.sources->count(); ++f) {
        const SourceFile& file = good.sources->file(f);
        out.sources->add(file.path(), f == good.mainFile ? text : file.text());
        out.sources->setImportedAt(f, good.sources->importedAt(f));
    }
    out.mainFile = good.mainFile;
    out.parsed = true;
    out.recovered = true;
    out.diagnostics = current.diagnostics;
    out.hiddenErrors = current.hiddenErrors;
    out.hiddenWarnings = current.hiddenWarnings;
    EditMap edit(good.sources->file(good.mainFile).text(), text);
    Mover move{edit, good.mainFile};
    for (const Occurrence& o : good.occurrences) {
        auto range = move.strict(o.range);
        if (!range) continue;
        Occurrence moved{*range, o.hover, std::nullopt, o.token};
        if (o.definition) {
            moved.definition = move.strict(*o.definition);
            if (!moved.definition) continue;  // its declaration is being edited
        }
        out.occurrences.push_back(std::move(moved));
    }
    for (Symbol s : good.symbols)
        if (move.symbol(s)) out.symbols.push_back(std::move(s));
    for (Scope s : good.scopes)
        if (auto range = move.spanning(s.range)) out.scopes.push_back({*range, std::move(s.names), s.pure});
    for (const Hint& h : good.hints)
        if (auto at = move.strict(h.at)) out.hints.push_back({*at, h.label, h.kind});
    out.globals = good.globals;
    out.members = good.members;
    out.imported = good.imported;  // (the current text's imports, as far as it parsed, too)
    out.imported.insert(current.imported.begin(), current.imported.end());
    return out;
}

}  // namespace psys::lsp
