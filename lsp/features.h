// The protocol's answers computed from an Analysis: diagnostics to publish, hover, go to
// definition, document symbols and completion. Pure functions of the analysis and a
// position, so tests call them without a transport.
#pragma once

#include <map>
#include <string>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "lsp/analysis.h"

namespace psys::lsp {

// Per file URI, the diagnostics to publish (the main file always has an entry, maybe empty).
std::map<std::string, nlohmann::json> diagnosticsByUri(const Analysis& a);

// One diagnostic as the protocol has it (its range in its own file).
nlohmann::json diagnosticJson(const Analysis& a, const Diagnostic& d);

// lsp/actions.cpp: the quick fixes of the main file's diagnostics that meet bytes [begin,
// end] (CodeAction[]); the edits that lay `text` out canonically, or why not (syntax errors).
nlohmann::json codeActions(const Analysis& a, uint32_t begin, uint32_t end);
std::variant<nlohmann::json, std::string> formatting(const std::string& path, const std::string& text);

// `offset` is a byte offset in the main file. Each returns the protocol's `null` when there is nothing.
nlohmann::json hover(const Analysis& a, uint32_t offset);
nlohmann::json definition(const Analysis& a, uint32_t offset);
nlohmann::json documentSymbols(const Analysis& a);
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
// The main file's names as semantic tokens (SemanticTokens), and the legend that reads them.
nlohmann::json semanticTokens(const Analysis& a);
nlohmann::json semanticTokensLegend();

// The language's own words by category (keywords, functions, constants, variables,
// types, attributes, integrators): `psysc builtins`, which the editor grammars' tests read.
nlohmann::json vocabulary();

}  // namespace psys::lsp
