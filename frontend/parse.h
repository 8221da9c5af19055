// Parsing one .psys file into an AST module (ANTLR4 parser generated from grammar/Psys.g4).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "frontend/ast.h"
#include "frontend/diagnostics.h"

namespace psys {

class ParseCache;

// Returns null when the file has syntax errors (they are reported to `diags`, several per
// file: the parser recovers and goes on). With a cache, the file's top-level declarations
// that an earlier parse through it saw are copied rather than parsed again (the same AST),
// and only those `keep` flags are in the module where it is given (ParseCache::parse).
std::unique_ptr<ast::Module> parseModule(int file, const SourceManager& sources, DiagnosticEngine& diags,
                                         ParseCache* cache = nullptr, const std::vector<bool>* keep = nullptr);

// Parses `text`, the bytes [shift, shift + text.size()) of `file` from a top-level
// declaration's start on, as a sequence of declarations; ranges are the file's. Where it
// does not parse: null, its syntax errors worded and reported when `report`, else at
// once. (An unknown type name is reported by the AST's builder, which returns the module.)
// Its tokens in `tokens` where given (the bytes of `text`, from 0), when it parses.
struct LexedToken;
std::unique_ptr<ast::Module> parseText(int file, std::string_view text, uint32_t shift, DiagnosticEngine& diags,
                                       bool report, std::vector<LexedToken>* tokens = nullptr);

// A token as the lexer found it: its type (grammar/Psys.g4's) and bytes [begin, end).
// Comments and white space are skipped, not tokens.
struct LexedToken {
    int type;
    uint32_t begin, end;
};

// A UTF-8 byte order mark: ANTLR's input stream drops one at the start of its text.
inline constexpr std::string_view kByteOrderMark = "\xEF\xBB\xBF";

// Character index (ANTLR decodes UTF-8 into code points) → byte offset, plus one past the end.
std::vector<uint32_t> codePointOffsets(const std::string& text);

}  // namespace psys
