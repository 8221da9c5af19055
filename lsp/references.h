// Where a name is declared and used: find references, document highlight and rename. The
// index records, for every name, the place of its declaration (Occurrence::definition):
// the uses of a declaration are the occurrences that name it, in the main file and every
// file it imports, and in each open document's analysis (a library's function is used
// by the files that import it). Declarations are compared by path and bytes, since each
// analysis numbers its files its own way.
#pragma once

#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "lsp/analysis.h"

namespace psys::lsp {

struct Declaration {
    std::string path, name;
    uint32_t begin = 0, end = 0;
    bool operator==(const Declaration&) const = default;
};

// The declaration of the name at `offset` of the main file (nullopt: no name there, or a built-in).
std::optional<Declaration> declarationAt(const Analysis& a, uint32_t offset);

// Locations ({uri, range}) of every use of `d` in `analyses`, each once, in file and
// position order; its declaration among them where `withDeclaration`.
nlohmann::json references(const std::vector<const Analysis*>& analyses, const Declaration& d, bool withDeclaration);

// The uses of the name at `offset` in the main file (DocumentHighlight: the declaration
// as a write, the rest as reads).
nlohmann::json highlights(const Analysis& a, uint32_t offset);

// What textDocument/prepareRename answers: the range of the name at `offset` and the name,
// or why it cannot be renamed (as rename would say).
std::variant<nlohmann::json, std::string> prepareRename(const Analysis& a, uint32_t offset);

// A rename's WorkspaceEdit, or why it is refused: not a name, a keyword, a built-in's
// name, a name already declared where one of the uses is, a declaration in the standard
// library, or no name at `offset`.
std::variant<nlohmann::json, std::string> rename(const std::vector<const Analysis*>& analyses, const Analysis& a,
                                                 uint32_t offset, const std::string& newName);

}  // namespace psys::lsp
