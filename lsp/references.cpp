#include "lsp/references.h"

#include <algorithm>
#include <map>
#include <set>
#include <tuple>

#include <fmt/format.h>

#include "frontend/builtins.h"
#include "lsp/positions.h"

namespace psys::lsp {

using nlohmann::json;

namespace {

std::string nameAt(const SourceManager& sources, SourceRange r) {
    return sources.file(r.file).text().substr(r.begin, r.end - r.begin);
}

Declaration declarationOf(const Analysis& a, SourceRange d) {
    return {a.sources->file(d.file).path(), nameAt(*a.sources, d), d.begin, d.end};
}

// A use: the file's path, its bytes and its range in the protocol's terms.
struct Use {
    std::string path;
    uint32_t begin, end;
    json range;
    bool declaration;
    bool operator<(const Use& o) const { return std::tie(path, begin, end) < std::tie(o.path, o.begin, o.end); }
};

std::vector<Use> usesOf(const std::vector<const Analysis*>& analyses, const Declaration& d) {
    std::set<Use> found;
    for (const Analysis* a : analyses) {
        if (!a || !a->parsed) continue;
        for (const Occurrence& o : a->occurrences) {
            if (!o.definition || !o.definition->valid() || !o.range.valid()) continue;
            if (declarationOf(*a, *o.definition) != d) continue;
            const SourceFile& f = a->sources->file(o.range.file);
            if (nameAt(*a->sources, o.range) != d.name) continue;  // (an import's path names its file, not a name)
            bool declaration = f.path() == d.path && o.range.begin == d.begin && o.range.end == d.end;
            found.insert({f.path(), o.range.begin, o.range.end, range(f, o.range.begin, o.range.end), declaration});
        }
    }
    return {found.begin(), found.end()};
}

bool isName(const std::string& s) {
    if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
    return std::all_of(s.begin(), s.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

// Why `name` cannot be a user's name, or "".
std::string reserved(const std::string& name) {
    if (!isName(name)) return fmt::format("`{}` is not a name (a letter or _, then letters, digits or _)", name);
    for (std::string_view k : keywords())
        if (k == name) return fmt::format("`{}` is a keyword", name);
    if (findBuiltinFunction(name) >= 0) return fmt::format("`{}` is a built-in function", name);
    if (findBuiltinConstant(name) >= 0) return fmt::format("`{}` is a built-in constant", name);
    if (isBuiltinVariable(name)) return fmt::format("`{}` is a built-in variable", name);
    return "";
}

// Why `name` would clash where the main file's uses are: a declaration of that name in
// a scope around one of them, or at file scope.
std::string clash(const Analysis& a, const std::vector<Use>& uses, const std::string& name) {
    for (const Name& n : a.globals)
        if (n.label == name) return fmt::format("`{}` is already declared ({})", name, n.detail);
    const std::string& main = a.sources->file(a.mainFile).path();
    for (const Use& u : uses) {
        if (u.path != main) continue;
        for (const Scope& s : a.scopes) {
            if (s.range.file != a.mainFile || u.begin < s.range.begin || u.end > s.range.end) continue;
            for (const Name& n : s.names)
                if (n.label == name) return fmt::format("`{}` is already declared where `{}` is used ({})", name, nameAt(*a.sources, {a.mainFile, u.begin, u.end}), n.detail);
        }
    }
    return "";
}

}  // namespace

std::optional<Declaration> declarationAt(const Analysis& a, uint32_t offset) {
    if (!a.parsed) return std::nullopt;
    const Occurrence* o = a.at(a.mainFile, offset);
    if (!o || !o->definition || !o->definition->valid() || o->definition->begin == o->definition->end) return std::nullopt;
    return declarationOf(a, *o->definition);
}

json references(const std::vector<const Analysis*>& analyses, const Declaration& d, bool withDeclaration) {
    json out = json::array();
    for (const Use& u : usesOf(analyses, d))
        if (withDeclaration || !u.declaration) out.push_back({{"uri", uriFromPath(u.path)}, {"range", u.range}});
    return out;
}

json highlights(const Analysis& a, uint32_t offset) {
    json out = json::array();
    auto d = declarationAt(a, offset);
    if (!d) return out;
    const std::string& main = a.sources->file(a.mainFile).path();
    for (const Use& u : usesOf({&a}, *d))
        if (u.path == main) out.push_back({{"range", u.range}, {"kind", u.declaration ? 3 : 2}});  // Write, Read
    return out;
}

std::variant<json, std::string> prepareRename(const Analysis& a, uint32_t offset) {
    auto d = declarationAt(a, offset);
    if (!d) return std::string("there is no name to rename here (a built-in's name cannot be renamed)");
    if (d->path.find("/std/") != std::string::npos)
        return fmt::format("`{}` is declared in the standard library ({})", d->name, d->path);
    const Occurrence* o = a.at(a.mainFile, offset);
    const SourceFile& f = a.sources->file(a.mainFile);
    return json{{"range", range(f, o->range.begin, o->range.end)}, {"placeholder", d->name}};
}

std::variant<json, std::string> rename(const std::vector<const Analysis*>& analyses, const Analysis& a, uint32_t offset,
                                       const std::string& newName) {
    auto d = declarationAt(a, offset);
    if (!d) return std::string("there is no name to rename here (a built-in's name cannot be renamed)");
    if (d->path.find("/std/") != std::string::npos)
        return fmt::format("`{}` is declared in the standard library ({})", d->name, d->path);
    if (newName == d->name) return json{{"changes", json::object()}};
    if (std::string why = reserved(newName); !why.empty()) return why;
    std::vector<Use> uses = usesOf(analyses, *d);
    if (std::string why = clash(a, uses, newName); !why.empty()) return why;
    json changes = json::object();
    for (const Use& u : uses) changes[uriFromPath(u.path)].push_back({{"range", u.range}, {"newText", newName}});
    return json{{"changes", changes}};
}

}  // namespace psys::lsp
