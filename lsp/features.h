// The protocol's answers computed from an Analysis: diagnostics to publish, hover, go to
// definition, document symbols and completion. Pure functions of the analysis and a
// position, so tests call them without a transport.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "frontend/parse.h"
#include "lsp/analysis.h"

namespace psys::lsp {

// Per file URI, the diagnostics to publish (the main file always has an entry, maybe empty).
std::map<std::string, nlohmann::json> diagnosticsByUri(const Analysis& a);

// One diagnostic as the protocol has it (its range in its own file).
nlohmann::json diagnosticJson(const Analysis& a, const Diagnostic& d);

// lsp/actions.cpp: the quick fixes of the main file's diagnostics that meet bytes [begin,
// end] (CodeAction[]); the edits that lay `text` out canonically, or why not (syntax errors).
nlohmann::json codeActions(const Analysis& a, uint32_t begin, uint32_t end);
// `parses`: the text is known to parse (its analysis is current), so it is not parsed again;
// `tokens`, where given, are its tokens (the document's parse cache), so it is not lexed.
std::variant<nlohmann::json, std::string> formatting(const std::string& path, const std::string& text, bool parses = false,
                                                     const std::vector<LexedToken>* tokens = nullptr);

// `offset` is a byte offset in the main file. Each returns the protocol's `null` when there is nothing.
nlohmann::json hover(const Analysis& a, uint32_t offset);
nlohmann::json definition(const Analysis& a, uint32_t offset);
// The outline (textDocument/documentSymbol's answer) as JSON text: of an analysis's main
// file, or of symbols moved into `file`.
std::string documentSymbols(const Analysis& a);
std::string documentSymbols(const SourceFile& file, const std::vector<Symbol>& symbols);
// The hints whose place is in [begin, end] of the main file.
nlohmann::json inlayHints(const Analysis& a, uint32_t begin, uint32_t end);

// `text` is the document as it is now, `offset` the cursor's byte in it; `scopes` come from
// the latest analysis that parsed (maybe of an older text: ranges are near enough).
nlohmann::json completion(const Analysis& scopes, const std::string& text, uint32_t offset);

// lsp/outline.cpp: folding ranges of the main file; the open documents' symbols whose
// names hold the query's letters in order (workspace/symbol); the signature of the call
// around the cursor with the argument it is in (`text` as now, as for completion).
nlohmann::json foldingRanges(const Analysis& a);
nlohmann::json workspaceSymbols(const std::vector<const Analysis*>& analyses, const std::string& query);
nlohmann::json signatureHelp(const Analysis& a, const std::string& text, uint32_t offset);
// The main file's names that begin in bytes [begin, end) as semantic tokens
// (SemanticTokens), and the legend that reads them; the edits that turn one token list's
// numbers into another's (SemanticTokensEdit[], for semanticTokens/full/delta).
nlohmann::json semanticTokens(const Analysis& a, uint32_t begin = 0, uint32_t end = UINT32_MAX);
nlohmann::json semanticTokensEdits(const nlohmann::json& before, const nlohmann::json& after);
nlohmann::json semanticTokensLegend();

// lsp/navigation.cpp: the main file's imports as links to their files (DocumentLink[]);
// the ranges around `offset`, innermost first (SelectionRange, each with its parent); the
// main file's diagnostics as a pull answers them (a full DocumentDiagnosticReport); a
// completion item with the documentation of a built-in word added.
nlohmann::json documentLinks(const Analysis& a);
nlohmann::json selectionRange(const Analysis& a, uint32_t offset);
nlohmann::json documentDiagnostics(const Analysis& a);
nlohmann::json resolveCompletion(nlohmann::json item);

// lsp/actions.cpp: the formatting edits that fall in bytes [begin, end] of `text` (each
// run of white space between two tokens is its own edit).
std::variant<nlohmann::json, std::string> rangeFormatting(const std::string& path, const std::string& text, uint32_t begin,
                                                          uint32_t end, bool parses = false,
                                                          const std::vector<LexedToken>* tokens = nullptr);

// The language's own words by category (keywords, functions, constants, variables,
// types, attributes, integrators): `psysc builtins`, which the editor grammars' tests read.
nlohmann::json vocabulary();

}  // namespace psys::lsp
