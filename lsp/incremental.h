// Analysing a document again after an edit by checking only what the edit can change.
//
// On a file of 20,000 lines an edit inside one object would otherwise check 2,500 objects
// and index them again. The last analysis keeps the main file's pieces as parsed (each
// top-level declaration's text: frontend/parse_cache.h), the names each uses and declares,
// every front-end diagnostic and where each declaration's index entries start. After an
// edit that changed some pieces and declared no new name, the pieces checked again are
// these, to a fixed point:
//   - a changed piece;
//   - a piece that uses a name one checked again declares (its types, its reads, its
//     emits and its errors may change with it);
//   - an object one checked again uses, before or after the edit (whether its equations
//     are read and whether it is created may change: every other user of it is checked
//     too, by the rule before).
// They are checked in a program of their own with what they use (the closure of the
// names used; the imports whole), told whether the rest spawns. Their diagnostics and
// index entries replace theirs in the last analysis; everything else is the last
// analysis's, moved to its place in the new text. The reports on the whole program
// ("never used", "never created", sizes once inlined) are made by every analysis whether
// or not it has errors (frontend.h's CheckOptions::allReports) and kept, and published
// only where a whole check would make them: so an edit that makes a program clean, or a
// clean one not, is followed too. What this cannot follow is analysed whole: a new or
// removed name, a changed import or file attribute, an imported object used by what
// changed, a program that reads `instance` (an extern read in a fold's term is an error
// then, wherever it is), and a function too large once inlined (no equation's size is
// reported then, anywhere).
// Tests: tests/lsp/incremental_test.cpp compares every sample's analysis after edits with
// a whole one's.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "lsp/analysis.h"

namespace psys::lsp {

// `text`'s analysis from `previous` (an analysis of the document's last text that parsed,
// made with a parse cache), or nullopt where it must be a whole one.
std::optional<Analysis> reanalyze(const std::string& path, const std::string& text, const Analysis& previous,
                                  const AnalyzeOptions& options);

// Sets `a`'s diagnostics from the front end's (`frontEnd`, sorted here by place, kept whole
// in a.frontEnd unless some were hidden already) and the passes' (after them): at most
// kMaxPublished errors and as many warnings of the front end's, the rest counted.
void publishable(Analysis& a, std::vector<Diagnostic> frontEnd, std::vector<Diagnostic> passes, int hiddenErrors,
                 int hiddenWarnings);

}  // namespace psys::lsp
