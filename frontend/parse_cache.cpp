// Parsing by top-level declaration, reusing the unchanged ones (frontend/parse_cache.h).
#include "frontend/parse_cache.h"

#include <algorithm>
#include <string_view>

#include "PsysLexer.h"

#include "frontend/parse.h"

namespace psys {

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
            while (i < text.size() && text[i] != '\n' && text[i] != '\r') ++i;  // (as the lexer's)
            continue;
        }
        if (c == '/' && i + 1 < text.size() && text[i + 1] == '*') {
            size_t end = text.find("*/", i + 2);
            i = end == std::string::npos ? text.size() : end + 1;
            continue;
        }
        if (c == ' ' || c == '\t' || c == '\r' || c == '\n') continue;  // (the lexer's white space, no more)
        // (An object's attributes on the lines before it are its own.)
        bool lineStart = i == 0 || text[i - 1] == '\n' || text[i - 1] == '\r';
        if (lineStart && (c == '@' || topKeyword(text, i)) && start != std::string::npos &&
            (depth > 0 || text[start] != '@'))
            close(i, false);
        if (start == std::string::npos) start = i;
        if (c == '"') {
            for (++i; i < text.size() && text[i] != '"' && text[i] != '\n' && text[i] != '\r'; ++i)
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

std::shared_ptr<const ParseCache::Piece> ParseCache::find(const std::string& text) {
    std::lock_guard lock(mutex_);
    auto it = pieces_.find(text);
    if (it == pieces_.end()) return nullptr;
    it->second->used = generation_;
    ++counts_.copied;
    return it->second;
}

namespace {

void declaredNames(const ast::ObjectDecl& o, std::vector<std::string>& out) {
    for (const auto& child : o.children) {
        out.push_back(child->name);
        declaredNames(*child, out);
    }
}

void sortUnique(std::vector<std::string>& names) {
    std::sort(names.begin(), names.end());
    names.erase(std::unique(names.begin(), names.end()), names.end());
}

// What lsp/incremental.h relates pieces by: the names a piece uses (a member after a `.` is
// the type's before it, not a declaration of the file) and the ones it declares.
void relate(ParsedPiece& piece, std::string_view text) {
    for (size_t i = 0; i < piece.tokens.size(); ++i) {
        const LexedToken& t = piece.tokens[i];
        if (t.type != grammar::PsysLexer::IDENT) continue;
        if (i > 0 && text.substr(piece.tokens[i - 1].begin, piece.tokens[i - 1].end - piece.tokens[i - 1].begin) == ".")
            continue;
        piece.mentions.emplace_back(text.substr(t.begin, t.end - t.begin));
    }
    sortUnique(piece.mentions);
    for (const ast::DeclPtr& d : piece.decls) {
        if (!d->name.empty()) piece.declares.push_back(d->name);
        if (d->kind == ast::DeclKind::Object) declaredNames(static_cast<const ast::ObjectDecl&>(*d), piece.declares);
    }
    sortUnique(piece.declares);
}

}  // namespace

std::shared_ptr<const ParseCache::Piece> ParseCache::piece(int file, std::string text, DiagnosticEngine& diags) {
    if (auto found = find(text)) return found;
    // Parsed alone at offset 0, errors kept apart: one that does not parse alone, or names
    // an unknown type, is parsed again with the rest of the file.
    DiagnosticEngine quiet(diags.sources());
    auto fresh = std::make_shared<Piece>();
    auto module = parseText(file, text, 0, quiet, false, &fresh->tokens);
    if (!module || quiet.errorCount() > 0) return nullptr;
    fresh->decls = std::move(module->decls);
    relate(*fresh, text);
    std::lock_guard lock(mutex_);
    fresh->used = generation_;
    ++counts_.parsed;
    return pieces_.emplace(std::move(text), std::move(fresh)).first->second;
}

std::unique_ptr<ast::Module> ParseCache::parse(int file, const std::string& text, DiagnosticEngine& diags,
                                               const std::vector<bool>* keep) {
    auto module = std::make_unique<ast::Module>();
    module->file = file;
    std::vector<TopDeclaration> tops = topLevelDeclarations(text);
    if (keep && keep->size() != tops.size()) keep = nullptr;
    // The pieces cover the text: each from the end of the one before to its own end (the
    // comments and white space before a declaration are its piece's).
    std::vector<size_t> declsBefore;  // module->decls.size() where each piece starts
    uint32_t from = 0;
    for (size_t k = 0; k < tops.size(); ++k) {
        declsBefore.push_back(module->decls.size());
        std::string key = text.substr(from, tops[k].end - from);
        // (A byte order mark the lexer drops at the start of its input, not elsewhere: a
        // piece after the first that starts with one is parsed with what comes before.)
        bool alone = !tops[k].unfinished && !(k > 0 && key.rfind(kByteOrderMark, 0) == 0);
        std::shared_ptr<const Piece> found = alone ? piece(file, std::move(key), diags) : nullptr;
        if (!found) {
            // From the declaration before this one (a missing token is reported just after
            // the last one matched, maybe that declaration's end) to the end of the file:
            // the whole file's parse from there on, the same errors at the same places.
            size_t restart = k == 0 ? 0 : k - 1;
            uint32_t begin = restart == 0 ? 0 : tops[restart - 1].end;
            module->decls.resize(declsBefore[restart]);
            auto rest = parseText(file, std::string_view(text).substr(begin), begin, diags, true);
            if (!rest) return nullptr;
            for (auto& d : rest->decls) module->decls.push_back(std::move(d));
            return module;
        }
        if (!keep || (*keep)[k])
            for (const ast::DeclPtr& d : found->decls) module->decls.push_back(ast::cloneParsed(*d, file, from));
        from = tops[k].end;
    }
    return module;
}

std::optional<std::vector<PieceAt>> ParseCache::pieces(const std::string& text) {
    std::vector<PieceAt> out;
    SourceManager noSources;  // (a piece's syntax errors are not reported: it is not a piece then)
    DiagnosticEngine none(noSources);
    uint32_t from = 0;
    for (const TopDeclaration& top : topLevelDeclarations(text)) {
        std::string key = text.substr(from, top.end - from);
        if (top.unfinished || (from > 0 && key.rfind(kByteOrderMark, 0) == 0)) return std::nullopt;
        auto found = piece(0, std::move(key), none);  // (any file: a copy gets its own)
        if (!found) return std::nullopt;
        out.push_back({from, top.end, found});
        from = top.end;
    }
    return out;
}

std::optional<std::vector<LexedToken>> ParseCache::tokens(const std::string& text) {
    std::vector<LexedToken> out;
    out.reserve(text.size() / 4);
    uint32_t from = 0;
    std::lock_guard lock(mutex_);
    for (const TopDeclaration& top : topLevelDeclarations(text)) {
        if (top.unfinished) return std::nullopt;
        auto it = pieces_.find(text.substr(from, top.end - from));
        if (it == pieces_.end()) return std::nullopt;
        it->second->used = generation_;
        for (LexedToken t : it->second->tokens) out.push_back({t.type, t.begin + from, t.end + from});
        from = top.end;
    }
    return out;
}

void ParseCache::sweep() {
    std::lock_guard lock(mutex_);
    for (auto it = pieces_.begin(); it != pieces_.end();)
        it = it->second->used + 1 < generation_ ? pieces_.erase(it) : std::next(it);
    ++generation_;
}

ParseCache::Counts ParseCache::counts() const {
    std::lock_guard lock(mutex_);
    Counts c = counts_;
    c.kept = pieces_.size();
    return c;
}

}  // namespace psys
