// Parsing a file again after an edit, by top-level declaration: the language server's
// documents change a line at a time, and parsing 20,000 lines with ANTLR takes most of a
// second, so a declaration whose text did not change is copied from its last parse
// (frontend/ast_clone.cpp) and only the changed ones are parsed.
//
// A file's top-level declarations end at a `;` or a `}` outside brackets, so the
// declarations' texts parse each on its own exactly as the whole file does (the grammar's
// `file` is a sequence of them). Where one does not parse alone, the text from the
// declaration before it to the end is parsed as the whole file would be, so that syntax
// errors are the same words at the same places as `psysc check`'s.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "frontend/ast.h"
#include "frontend/diagnostics.h"
#include "frontend/parse.h"

namespace psys {

struct TopDeclaration {
    uint32_t begin, end;  // [begin, end) of the text
    bool unfinished;      // cut off (by the next declaration's keyword, or the end) before its `;` or `}`
};

// The top-level declarations of `text`, found by brackets, semicolons and declaration
// keywords at the start of a line (comments and strings skipped; each begins at its first
// token). A keyword or attribute at the start of a line begins a new one even where the
// one before is unfinished, so that a missing `}` does not swallow the rest of the file.
std::vector<TopDeclaration> topLevelDeclarations(const std::string& text);

// A top-level declaration's text as parsed alone (at offset 0), and the names that the
// language server's incremental analysis relates declarations by (lsp/incremental.h).
struct ParsedPiece {
    std::vector<ast::DeclPtr> decls;
    std::vector<LexedToken> tokens;
    std::vector<std::string> mentions;  // its identifiers but those after a `.`, sorted, once each
    std::vector<std::string> declares;  // its declarations' names and their nested objects', sorted
    uint64_t used = 0;                  // the generation that last used it
};

// A piece of a text: the declaration parsed, and the comments and white space before it.
struct PieceAt {
    uint32_t begin, end;
    std::shared_ptr<const ParsedPiece> parsed;
};

// One per document (shared between the threads that analyse it).
class ParseCache {
public:
    // The module of `text` (the file `file`), or null with its syntax errors reported.
    // Where `keep` is given (one flag a piece of `pieces(text)`), only the pieces flagged are
    // in the module: the rest of the file is known from elsewhere.
    std::unique_ptr<ast::Module> parse(int file, const std::string& text, DiagnosticEngine& diags,
                                       const std::vector<bool>* keep = nullptr);
    // Every piece of `text`, each parsed alone; nullopt where one does not parse alone (a
    // syntax error, an unfinished declaration).
    std::optional<std::vector<PieceAt>> pieces(const std::string& text);
    // The tokens of `text` where every declaration of it is held (as parsed: it has no
    // syntax error), so that the layout need not lex it again (frontend/format.h).
    std::optional<std::vector<LexedToken>> tokens(const std::string& text);
    // Forgets the declarations that no parse has used since the sweep before this one
    // (the last two texts' are kept: an analysis of the next may start from either).
    void sweep();

    struct Counts {
        int copied = 0, parsed = 0;  // declarations' texts, since the cache was made
        size_t kept = 0;             // texts held now
    };
    Counts counts() const;

private:
    using Piece = ParsedPiece;
    std::shared_ptr<const Piece> find(const std::string& text);
    // The piece of `text` found or parsed alone; null where it does not parse alone.
    std::shared_ptr<const Piece> piece(int file, std::string text, DiagnosticEngine& diags);

    mutable std::mutex mutex_;
    std::unordered_map<std::string, std::shared_ptr<Piece>> pieces_;
    uint64_t generation_ = 1;
    Counts counts_;
};

}  // namespace psys
