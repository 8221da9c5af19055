#include "lsp/recover.h"

#include <algorithm>
#include <optional>
#include <string_view>

namespace psys::lsp {

namespace {

// Where each line of `text` starts, and its end (the text's size) last.
std::vector<uint32_t> lineStarts(const std::string& text) {
    std::vector<uint32_t> starts = {0};
    for (uint32_t i = 0; i < text.size(); ++i)
        if (text[i] == '\n') starts.push_back(i + 1);
    if (starts.back() != text.size()) starts.push_back(static_cast<uint32_t>(text.size()));
    return starts;
}

enum class Step : uint8_t { Same, Delete, Insert };

// The shortest edit script from the lines `a` to the lines `b` (Myers, "An O(ND)
// difference algorithm", 1986: O((N+M)·D) time for D lines deleted or inserted), or nullopt
// where it is longer than `maxEdits`. (Written here: Debian's dtl, the library at hand,
// has a header clang refuses.)
std::optional<std::vector<Step>> lineScript(const std::vector<std::string_view>& a, const std::vector<std::string_view>& b,
                                            int maxEdits) {
    const int n = static_cast<int>(a.size()), m = static_cast<int>(b.size()), mid = maxEdits + 1;
    std::vector<int> v(static_cast<size_t>(2 * maxEdits + 3), 0);  // per diagonal k = x - y: the furthest x
    std::vector<std::vector<int>> trace;                            // v as each round began
    auto at = [&](std::vector<int>& w, int k) -> int& { return w[static_cast<size_t>(mid + k)]; };
    for (int d = 0; d <= maxEdits; ++d) {
        trace.push_back(v);
        for (int k = -d; k <= d; k += 2) {
            int x = (k == -d || (k != d && at(v, k - 1) < at(v, k + 1))) ? at(v, k + 1) : at(v, k - 1) + 1;
            int y = x - k;
            while (x < n && y < m && a[static_cast<size_t>(x)] == b[static_cast<size_t>(y)]) ++x, ++y;
            at(v, k) = x;
            if (x < n || y < m) continue;
            // Back from the end, round by round: the snake, then the one step before it.
            std::vector<Step> script;
            for (int e = d; e >= 0; --e) {
                std::vector<int>& w = trace[static_cast<size_t>(e)];
                int kk = x - y;
                int prevK = (kk == -e || (kk != e && at(w, kk - 1) < at(w, kk + 1))) ? kk + 1 : kk - 1;
                int prevX = at(w, prevK), prevY = prevX - prevK;
                while (x > prevX && y > prevY) script.push_back(Step::Same), --x, --y;
                if (e > 0) script.push_back(x == prevX ? Step::Insert : Step::Delete);
                x = prevX, y = prevY;
            }
            std::reverse(script.begin(), script.end());
            return script;
        }
    }
    return std::nullopt;
}

std::vector<std::string_view> lines(const std::string& text, const std::vector<uint32_t>& starts) {
    std::vector<std::string_view> out;
    for (size_t i = 0; i + 1 < starts.size(); ++i) out.push_back(std::string_view(text).substr(starts[i], starts[i + 1] - starts[i]));
    return out;
}

}  // namespace

// Past this many lines deleted and inserted (a file re-indented, pasted over) the line
// script is not worth its time and memory: what lies between the common first and last
// lines is one edit.
constexpr int kMaxEdits = 500;

EditMap::EditMap(const std::string& older, const std::string& current) {
    // The lines the texts share, by a shortest edit script over lines (Myers's algorithm,
    // O((N+M)·D) for D differing lines), then each run of differing lines
    // narrowed to the characters that differ (an edit inside a line keeps the names
    // before and after it on that line).
    std::vector<uint32_t> olderStarts = lineStarts(older), currentStarts = lineStarts(current);
    std::vector<std::string_view> a = lines(older, olderStarts), b = lines(current, currentStarts);
    // The lines both texts begin and end with are the same; between them, the script.
    size_t head = 0, tail = 0;
    while (head < a.size() && head < b.size() && a[head] == b[head]) ++head;
    while (tail < a.size() - head && tail < b.size() - head && a[a.size() - 1 - tail] == b[b.size() - 1 - tail]) ++tail;
    std::vector<std::string_view> midA(a.begin() + long(head), a.end() - long(tail)),
        midB(b.begin() + long(head), b.end() - long(tail));
    std::vector<Step> script(head, Step::Same);
    if (auto middle = lineScript(midA, midB, kMaxEdits)) {
        script.insert(script.end(), middle->begin(), middle->end());
    } else {
        script.insert(script.end(), midA.size(), Step::Delete);
        script.insert(script.end(), midB.size(), Step::Insert);
    }
    script.insert(script.end(), tail, Step::Same);
    uint32_t i = 0, j = 0;  // lines of each
    auto flush = [&](uint32_t i0, uint32_t j0) {
        if (i0 == i && j0 == j) return;
        uint32_t ob = olderStarts[i0], oe = olderStarts[i], cb = currentStarts[j0], ce = currentStarts[j];
        while (ob < oe && cb < ce && older[ob] == current[cb]) ++ob, ++cb;
        while (oe > ob && ce > cb && older[oe - 1] == current[ce - 1]) --oe, --ce;
        hunks_.push_back({ob, oe, cb, ce});
    };
    uint32_t i0 = 0, j0 = 0;
    for (Step step : script) {
        if (step == Step::Same) {
            flush(i0, j0);
            ++i, ++j;
            i0 = i, j0 = j;
        } else if (step == Step::Delete) {
            ++i;
        } else {
            ++j;
        }
    }
    flush(i0, j0);
}

// One way through the hunks: `from` and `to` pick each hunk's two sides.
std::optional<uint32_t> EditMap::through(uint32_t at, bool after, Side from, Side to) const {
    int64_t shift = 0;
    for (const Hunk& h : hunks_) {
        auto [fromBegin, fromEnd] = side(h, from);
        auto [toBegin, toEnd] = side(h, to);
        if (at < fromBegin) break;
        if (at == fromBegin && at == fromEnd) return after ? toEnd : toBegin;
        if (at == fromBegin) return toBegin;
        if (at < fromEnd) return std::nullopt;
        shift = int64_t(toEnd) - int64_t(fromEnd);
    }
    return static_cast<uint32_t>(int64_t(at) + shift);
}

std::optional<uint32_t> EditMap::toCurrent(uint32_t older, bool after) const {
    return through(older, after, Side::Older, Side::Current);
}

bool EditMap::touches(uint32_t begin, uint32_t end) const {
    for (const Hunk& h : hunks_) {
        if (h.olderBegin >= end) break;
        bool inside = h.olderBegin == h.olderEnd ? begin < h.olderBegin && h.olderBegin < end  // an insertion
                                                 : h.olderBegin < end && h.olderEnd > begin;
        if (inside) return true;
    }
    return false;
}

std::optional<uint32_t> EditMap::toOlder(uint32_t current, bool after) const {
    return through(current, after, Side::Current, Side::Older);
}

namespace {

struct Mover {
    const EditMap& edit;
    int main;

    // A place in the main file moved, or nullopt where the edit touched it; other files' as they are.
    std::optional<SourceRange> strict(SourceRange r) const {
        if (r.file != main) return r;
        if (edit.touches(r.begin, r.end)) return std::nullopt;
        auto b = edit.toCurrent(r.begin, true), e = edit.toCurrent(r.end);
        if (!b || !e || *e < *b) return std::nullopt;
        return SourceRange{r.file, *b, *e};
    }
    // A declaration's whole range: where the edit is inside it, it still spans the edit.
    std::optional<SourceRange> spanning(SourceRange r) const {
        if (r.file != main) return r;
        auto b = edit.toCurrent(r.begin, true), e = edit.toCurrent(r.end);
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

Analysis recover(const Analysis& good, const Analysis& current, const std::string& text, bool readsOnly) {
    Analysis out;
    out.sources = std::make_unique<SourceManager>();
    for (int f = 0; f < good.sources->count(); ++f) {
        const SourceFile& file = good.sources->file(f);
        out.sources->add(file.path(), f == good.mainFile ? text : file.text());
        out.sources->setImportedAt(f, good.sources->importedAt(f));
    }
    out.mainFile = good.mainFile;
    out.parsed = true;
    out.milliseconds = current.milliseconds;
    out.recovered = true;
    out.diagnostics = current.diagnostics;
    out.passesRan = current.passesRan;
    out.passDiagnostics = current.passDiagnostics;
    out.hiddenErrors = current.hiddenErrors;
    out.hiddenWarnings = current.hiddenWarnings;
    EditMap edit(good.sources->file(good.mainFile).text(), text);
    Mover move{edit, good.mainFile};
    out.occurrences.reserve(good.occurrences.size());
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
    out.symbols = movedSymbols(good, edit);
    for (const Hint& h : good.hints)
        if (auto at = move.strict(h.at)) out.hints.push_back({*at, h.label, h.kind});
    out.passHints = out.hints.size();
    if (readsOnly) return out;
    for (const Scope& s : good.scopes)
        if (auto range = move.spanning(s.range)) out.scopes.push_back({*range, s.names, s.pure});
    out.globals = good.globals;
    out.members = good.members;
    out.imported = good.imported;  // (the current text's imports, as far as it parsed, too)
    out.imported.insert(current.imported.begin(), current.imported.end());
    return out;
}

std::vector<Symbol> movedSymbols(const Analysis& a, const EditMap& edit) {
    Mover move{edit, a.mainFile};
    std::vector<Symbol> out;
    for (Symbol s : a.symbols)
        if (move.symbol(s)) out.push_back(std::move(s));
    return out;
}

void carryPasses(const Analysis& passed, Analysis& fresh) {
    if (passed.mainFile < 0 || fresh.mainFile < 0 || !passed.passesRan) return;
    EditMap edit(passed.sources->file(passed.mainFile).text(), fresh.sources->file(fresh.mainFile).text());
    Mover move{edit, passed.mainFile};
    // The files by number in each analysis (an edit to the imports renumbers them): an
    // imported file's places carry where it is loaded with the same text.
    auto place = [&](SourceRange r) -> std::optional<SourceRange> {
        if (!r.valid()) return r;
        if (r.file == passed.mainFile) {
            auto moved = move.strict(r);
            if (moved) moved->file = fresh.mainFile;
            return moved;
        }
        const SourceFile& from = passed.sources->file(r.file);
        for (int f = 0; f < fresh.sources->count(); ++f)
            if (f != fresh.mainFile && fresh.sources->file(f).path() == from.path())
                return fresh.sources->file(f).text() == from.text() ? std::optional(SourceRange{f, r.begin, r.end}) : std::nullopt;
        return std::nullopt;
    };
    for (size_t i = passed.passDiagnostics; i < passed.diagnostics.size(); ++i) {
        Diagnostic d = passed.diagnostics[i];
        auto range = place(d.range);
        if (!range) continue;
        std::optional<uint32_t> focus;
        if (d.focus && range->file == fresh.mainFile && d.range.file == passed.mainFile) focus = edit.toCurrent(*d.focus);
        else if (d.focus) focus = d.focus;
        d.range = *range, d.focus = focus;
        std::vector<DiagnosticNote> notes;
        for (DiagnosticNote& n : d.notes)
            if (auto at = place(n.range)) notes.push_back({*at, std::move(n.message)});
        std::vector<FixIt> fixes;
        for (FixIt& f : d.fixes)
            if (auto at = place(f.range)) fixes.push_back({std::move(f.title), *at, std::move(f.replacement)});
        d.notes = std::move(notes), d.fixes = std::move(fixes);
        fresh.diagnostics.push_back(std::move(d));
    }
    for (size_t i = passed.passHints; i < passed.hints.size(); ++i)
        if (auto at = place(passed.hints[i].at)) fresh.hints.push_back({*at, passed.hints[i].label, passed.hints[i].kind});
}

}  // namespace psys::lsp
