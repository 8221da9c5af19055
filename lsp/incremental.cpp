// Re-checking only what an edit can change (lsp/incremental.h).
#include "lsp/incremental.h"

#include <algorithm>
#include <chrono>
#include <string_view>
#include <unordered_map>

#include "frontend/frontend.h"
#include "frontend/loader.h"
#include "lsp/index_builder.h"

namespace psys::lsp {

namespace {

bool declares(const ParsedPiece& piece, ast::DeclKind kind) {
    return std::any_of(piece.decls.begin(), piece.decls.end(), [&](const ast::DeclPtr& d) { return d->kind == kind; });
}

std::string_view textOf(const std::string& text, const PieceAt& p) {
    return std::string_view(text).substr(p.begin, p.end - p.begin);
}

// Which pieces of the new text are checked again, and which are loaded to check them.
struct Plan {
    std::vector<bool> checked, loaded;
};

bool sameShape(const ParsedPiece& a, const ParsedPiece& b) {
    if (a.decls.size() != b.decls.size() || a.declares != b.declares) return false;
    for (size_t i = 0; i < a.decls.size(); ++i)
        if (a.decls[i]->kind != b.decls[i]->kind || a.decls[i]->name != b.decls[i]->name) return false;
    return !declares(b, ast::DeclKind::Import) && !declares(b, ast::DeclKind::Attribute);
}

std::optional<Plan> plan(const std::string& before, const std::vector<PieceAt>& was, const std::string& text,
                         const std::vector<PieceAt>& now) {
    if (was.size() != now.size()) return std::nullopt;
    const size_t n = now.size();
    std::unordered_map<std::string_view, std::vector<size_t>> usedBy, declaredBy;
    for (size_t k = 0; k < n; ++k) {
        for (const std::string& name : now[k].parsed->mentions) usedBy[name].push_back(k);
        for (const std::string& name : now[k].parsed->declares) declaredBy[name].push_back(k);
    }
    Plan p{std::vector<bool>(n), std::vector<bool>(n)};
    std::vector<size_t> work;
    auto check = [&](size_t k) {
        if (!p.checked[k]) p.checked[k] = true, work.push_back(k);
    };
    auto objectsUsed = [&](const std::vector<std::string>& names) {
        for (const std::string& name : names)
            if (auto it = declaredBy.find(name); it != declaredBy.end())
                for (size_t k : it->second)
                    if (declares(*now[k].parsed, ast::DeclKind::Object)) check(k);
    };
    for (size_t k = 0; k < n; ++k) {
        if (textOf(before, was[k]) == textOf(text, now[k])) continue;
        if (!sameShape(*was[k].parsed, *now[k].parsed)) return std::nullopt;
        check(k);
        objectsUsed(was[k].parsed->mentions);  // (what it read before the edit)
    }
    while (!work.empty()) {
        size_t k = work.back();
        work.pop_back();
        for (const std::string& name : now[k].parsed->declares)
            if (auto it = usedBy.find(name); it != usedBy.end())
                for (size_t user : it->second) check(user);
        objectsUsed(now[k].parsed->mentions);
    }
    // What the pieces checked again use, transitively; every import and file attribute,
    // and the first piece (where a quick fix puts an import in a file without one).
    for (size_t k = 0; k < n; ++k) {
        p.loaded[k] = p.checked[k] || k == 0 || declares(*now[k].parsed, ast::DeclKind::Import) ||
                      declares(*now[k].parsed, ast::DeclKind::Attribute);
        if (p.loaded[k]) work.push_back(k);
    }
    while (!work.empty()) {
        size_t k = work.back();
        work.pop_back();
        for (const std::string& name : now[k].parsed->mentions)
            if (auto it = declaredBy.find(name); it != declaredBy.end())
                for (size_t d : it->second)
                    if (!p.loaded[d]) p.loaded[d] = true, work.push_back(d);
    }
    return p;
}

// Places in the last analysis's main file moved to the new text: each piece by where it
// starts now. A place inside a piece checked again is not moved (nullopt).
class PieceMover {
public:
    PieceMover(int file, const std::vector<PieceAt>& was, const std::vector<PieceAt>& now, const std::vector<bool>& checked)
        : file_(file), was_(was), now_(now), checked_(checked) {}

    // The piece of the last text that `offset` lies in (the last one for the text's end).
    size_t pieceOf(uint32_t offset) const {
        auto it = std::upper_bound(was_.begin(), was_.end(), offset, [](uint32_t o, const PieceAt& p) { return o < p.begin; });
        return it == was_.begin() ? 0 : size_t(it - was_.begin()) - 1;
    }
    bool inChecked(const SourceRange& r) const { return r.file == file_ && !was_.empty() && checked_[pieceOf(r.begin)]; }

    bool move(SourceRange& r) const {
        if (r.file != file_ || was_.empty()) return true;
        auto offset = [&](uint32_t& o, uint32_t inside) {
            size_t k = pieceOf(inside);
            if (checked_[k]) return false;
            o = o - was_[k].begin + now_[k].begin;
            return true;
        };
        uint32_t begin = r.begin;
        return offset(r.end, r.end > begin ? r.end - 1 : begin) && offset(r.begin, begin);
    }
    bool move(std::optional<SourceRange>& r) const { return !r || move(*r); }
    bool move(Symbol& s) const {
        bool ok = move(s.range) && move(s.selection);
        for (Symbol& c : s.children) ok = ok && move(c);
        return ok;
    }
    bool move(Diagnostic& d) const {
        bool ok = move(d.range);
        for (DiagnosticNote& note : d.notes) ok = ok && move(note.range);
        for (FixIt& fix : d.fixes) ok = ok && move(fix.range);
        if (d.focus && ok) {
            SourceRange f{d.range.file, *d.focus, *d.focus};
            ok = move(f);
            d.focus = f.begin;
        }
        return ok;
    }

private:
    int file_;
    const std::vector<PieceAt>& was_;
    const std::vector<PieceAt>& now_;
    const std::vector<bool>& checked_;
};

// Appends `from`'s index entries [begin, end) to `out`, each moved (where `mover` is given).
bool append(Analysis& out, const Analysis& from, const IndexMark& begin, const IndexMark& end, const PieceMover* mover) {
    auto copy = [&](auto& to, const auto& source, size_t b, size_t e) {
        for (size_t i = b; i < e; ++i) to.push_back(source[i]);
    };
    size_t o = out.occurrences.size(), s = out.symbols.size(), sc = out.scopes.size(), h = out.hints.size(),
           in = out.integrating.size();
    copy(out.occurrences, from.occurrences, begin.occurrences, end.occurrences);
    copy(out.symbols, from.symbols, begin.symbols, end.symbols);
    copy(out.globals, from.globals, begin.globals, end.globals);
    copy(out.scopes, from.scopes, begin.scopes, end.scopes);
    copy(out.hints, from.hints, begin.hints, end.hints);
    copy(out.integrating, from.integrating, begin.integrating, end.integrating);
    copy(out.members, from.members, begin.members, end.members);
    if (!mover) return true;
    bool ok = true;
    for (size_t i = o; i < out.occurrences.size(); ++i)
        ok = ok && mover->move(out.occurrences[i].range) && mover->move(out.occurrences[i].definition);
    for (size_t i = s; i < out.symbols.size(); ++i) ok = ok && mover->move(out.symbols[i]);
    for (size_t i = sc; i < out.scopes.size(); ++i) ok = ok && mover->move(out.scopes[i].range);
    for (size_t i = h; i < out.hints.size(); ++i) ok = ok && mover->move(out.hints[i].at);
    for (size_t i = in; i < out.integrating.size(); ++i) ok = ok && mover->move(out.integrating[i]);
    return ok;
}

IndexMark markOf(const Analysis& a) {
    return {0, a.occurrences.size(), a.symbols.size(), a.globals.size(), a.scopes.size(), a.hints.size(),
            a.integrating.size(), a.members.size()};
}

// The same imported files, with the same texts, numbered the same.
bool sameImports(const Analysis& previous, const SourceManager& sources, int mainFile) {
    if (sources.count() != previous.sources->count() || mainFile != previous.mainFile) return false;
    for (int f = 0; f < sources.count(); ++f)
        if (f != mainFile && (sources.file(f).path() != previous.sources->file(f).path() ||
                              sources.file(f).text() != previous.sources->file(f).text()))
            return false;
    return true;
}

void objectNames(const ast::ObjectDecl& o, std::vector<std::string>& out) {
    out.push_back(o.name);
    for (const auto& child : o.children) objectNames(*child, out);
}

// An imported file that names a declaration of the main file (one namespace): its check
// depends on the main file's, which this does not follow.
bool importUsesMain(const SourceManager& sources, int mainFile, const std::vector<PieceAt>& now, ParseCache& cache) {
    std::unordered_map<std::string_view, bool> declared;
    for (const PieceAt& p : now)
        for (const std::string& name : p.parsed->declares) declared[name] = true;
    for (int f = 0; f < sources.count(); ++f) {
        if (f == mainFile) continue;
        auto pieces = cache.pieces(sources.file(f).text());
        if (!pieces) return true;
        for (const PieceAt& p : *pieces)
            for (const std::string& name : p.parsed->mentions)
                if (declared.count(name)) return true;
    }
    return false;
}

// What the pieces not loaded declare, for the checker's did-you-mean.
void declaredElsewhere(const std::vector<PieceAt>& now, const std::vector<bool>& loaded, CheckOptions& out) {
    for (size_t k = 0; k < now.size(); ++k) {
        if (loaded[k]) continue;
        for (const ast::DeclPtr& d : now[k].parsed->decls) {
            switch (d->kind) {
                case ast::DeclKind::Const: case ast::DeclKind::Fn: case ast::DeclKind::Extern:
                case ast::DeclKind::Trigger: case ast::DeclKind::Object: break;
                default: continue;
            }
            out.declaredElsewhere.emplace_back(d->name, d->kind);
            if (d->kind == ast::DeclKind::Object) {
                std::vector<std::string> nested;
                objectNames(static_cast<const ast::ObjectDecl&>(*d), nested);
                out.nestedElsewhere.insert(out.nestedElsewhere.end(), nested.begin() + 1, nested.end());
            }
        }
    }
}

// An object of an imported file that a piece checked again names: its equations' uses are
// the main file's too, which this does not follow.
bool usesImportedObject(const ast::Program& program, const std::vector<PieceAt>& now, const std::vector<bool>& checked) {
    std::vector<std::string> names;
    for (const auto& m : program.modules)
        if (m.get() != &program.main())
            for (const auto& d : m->decls)
                if (d->kind == ast::DeclKind::Object) objectNames(static_cast<const ast::ObjectDecl&>(*d), names);
    for (size_t k = 0; k < now.size(); ++k)
        if (checked[k])
            for (const std::string& name : names)
                if (std::binary_search(now[k].parsed->mentions.begin(), now[k].parsed->mentions.end(), name)) return true;
    return false;
}

// The index of the new text: the imports' and the unchanged declarations' from the last
// analysis (moved), the checked ones' from the checked program's; false where a place of
// the last analysis lies in a piece checked again.
bool mergeIndex(Analysis& a, const Analysis& previous, const Analysis& checked, const PieceMover& mover,
                const PieceMover& fresh, const std::vector<bool>& isChecked, const std::vector<PieceAt>& now) {
    if (!append(a, previous, IndexMark{}, previous.marks.front(), nullptr)) return false;
    size_t next = 0;  // the checked program's next main declaration
    for (size_t i = 0; i + 1 < previous.marks.size(); ++i) {
        size_t k = mover.pieceOf(previous.marks[i].begin);
        a.marks.push_back(markOf(a));
        if (isChecked[k]) {
            while (next + 1 < checked.marks.size() && fresh.pieceOf(checked.marks[next].begin) < k) ++next;
            if (next + 1 >= checked.marks.size() || fresh.pieceOf(checked.marks[next].begin) != k) return false;
            a.marks.back().begin = checked.marks[next].begin;
            append(a, checked, checked.marks[next], checked.marks[next + 1], nullptr);
            ++next;
        } else {
            a.marks.back().begin = previous.marks[i].begin - previous.pieces[k].begin + now[k].begin;
            if (!append(a, previous, previous.marks[i], previous.marks[i + 1], &mover)) return false;
        }
    }
    a.marks.push_back(markOf(a));
    a.marks.back().begin = UINT32_MAX;
    return true;
}

}  // namespace

std::optional<Analysis> reanalyze(const std::string& path, const std::string& text, const Analysis& previous,
                                  const AnalyzeOptions& options) {
    auto started = std::chrono::steady_clock::now();
    if (!previous.parsed || previous.recovered || !previous.frontEnd || previous.instanced || previous.mainFile < 0 ||
        previous.pieces.empty() || previous.marks.empty())
        return std::nullopt;
    const std::string& before = previous.sources->file(previous.mainFile).text();
    auto now = options.cache->pieces(text);
    if (!now) return std::nullopt;
    auto p = plan(before, previous.pieces, text, *now);
    if (!p) return std::nullopt;

    Analysis a;
    a.sources = std::make_unique<SourceManager>();
    DiagnosticEngine diags(*a.sources);
    diags.setLimit(kMaxKept);
    auto program = loadProgramFromText(path, text, *a.sources, diags, options.open, options.cache, &p->loaded);
    if (!program || diags.errorCount() > 0) return std::nullopt;
    a.mainFile = program->main().file;
    if (!sameImports(previous, *a.sources, a.mainFile) || usesImportedObject(*program, *now, p->checked) ||
        importUsesMain(*a.sources, a.mainFile, *now, *options.cache))
        return std::nullopt;

    PieceMover mover(previous.mainFile, previous.pieces, *now, p->checked);
    CheckOptions check{.allReports = true};
    declaredElsewhere(*now, p->loaded, check);
    for (size_t k = 0; k < now->size(); ++k)
        if (!p->loaded[k])
            check.spawnsElsewhere |= declares(*(*now)[k].parsed, ast::DeclKind::Spawn) ||
                                     declares(*(*now)[k].parsed, ast::DeclKind::Trigger);
    checkProgram(*program, diags, check);
    if (program->instanced || diags.hiddenErrors() > 0 || diags.hiddenWarnings() > 0) return std::nullopt;

    // The diagnostics: the checked pieces' new ones, everything else's moved; every report
    // on the whole program among them (whether it is published is the whole program's
    // question: publishable). A function too large once inlined silences the equations'
    // sizes everywhere: not followed.
    PieceMover fresh(a.mainFile, *now, *now, p->checked);  // (inChecked on the new text's places)
    std::vector<Diagnostic> all;
    for (Diagnostic& d : diags.take())
        if (fresh.inChecked(d.range)) all.push_back(std::move(d));
    for (const Diagnostic& d : *previous.frontEnd) {
        if (mover.inChecked(d.range)) continue;
        all.push_back(d);
        if (!mover.move(all.back())) return std::nullopt;
    }
    if (std::any_of(all.begin(), all.end(), [](const Diagnostic& d) { return d.report == ProgramReport::InlinedSize; }))
        return std::nullopt;
    // (A whole check keeps the first kMaxKept in the order it makes them, and offers no
    // did-you-mean past them.)
    if (all.size() >= size_t(kMaxKept)) return std::nullopt;

    Analysis checked;
    buildIndex(*program, *a.sources, checked);
    if (!mergeIndex(a, previous, checked, mover, fresh, p->checked, *now)) return std::nullopt;

    a.parsed = true;
    a.incremental = true;
    a.pieces = std::move(*now);
    for (int f = 0; f < a.sources->count(); ++f)
        if (f != a.mainFile) a.imported.insert(sourceKey(a.sources->file(f).path()));
    a.passHints = a.hints.size();
    publishable(a, std::move(all), {}, 0, 0);
    a.milliseconds = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started).count();
    return a;
}

void publishable(Analysis& a, std::vector<Diagnostic> frontEnd, std::vector<Diagnostic> passes, int hiddenErrors,
                 int hiddenWarnings) {
    std::stable_sort(frontEnd.begin(), frontEnd.end(), [](const Diagnostic& x, const Diagnostic& y) {
        return std::pair(x.range.file, x.range.begin) < std::pair(y.range.file, y.range.begin);
    });
    if (hiddenErrors == 0 && hiddenWarnings == 0)
        a.frontEnd = std::make_shared<const std::vector<Diagnostic>>(frontEnd);
    a.diagnostics.clear();
    int shownErrors = 0, shownWarnings = 0;
    PublishedReports published = publishedReports(frontEnd);
    for (Diagnostic& d : frontEnd) {
        if (!published(d)) continue;
        int& shown = d.severity == Severity::Error ? shownErrors : shownWarnings;
        int& hidden = d.severity == Severity::Error ? hiddenErrors : hiddenWarnings;
        if (d.severity != Severity::Error && d.severity != Severity::Warning) {
            a.diagnostics.push_back(std::move(d));
        } else if (shown < kMaxPublished) {
            ++shown;
            a.diagnostics.push_back(std::move(d));
        } else {
            ++hidden;
        }
    }
    a.passDiagnostics = a.diagnostics.size();
    for (Diagnostic& d : passes) a.diagnostics.push_back(std::move(d));
    a.hiddenErrors = hiddenErrors;
    a.hiddenWarnings = hiddenWarnings;
}

}  // namespace psys::lsp
