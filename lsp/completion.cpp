// Completion: what may be written at the cursor. After `name.`, what an enclosing object
// offers to be read live (only an enclosing one: elsewhere `rocket.` offers nothing), or a
// vector's components; after `@`, the attributes; inside `@integrator(`, the methods;
// elsewhere the names in scope (the object's, fn's or trigger's own, then the file's), the
// built-ins (`instance` and, after `instance.`, its members) and the keywords that can be
// written there — in a fn's body only what a fn may read (no age, time or dt, no externs,
// objects or triggers, no history).
#include <algorithm>
#include <cctype>
#include <set>

#include "frontend/builtins.h"
#include "frontend/types.h"
#include "lsp/features.h"

namespace psys::lsp {

namespace {

bool identChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

nlohmann::json item(const Name& n) {
    nlohmann::json j = {{"label", n.label}, {"kind", static_cast<int>(n.kind)}};
    if (!n.detail.empty()) j["detail"] = n.detail;
    if (!n.documentation.empty()) j["documentation"] = n.documentation;
    return j;
}

std::vector<Name> builtinNames() {
    std::vector<Name> names;
    for (std::string_view k : keywords()) names.push_back({std::string(k), "", "", CompletionKind::Keyword});
    for (const BuiltinFunction& f : builtinFunctions())
        names.push_back({std::string(f.name), std::string(f.signature), "built-in function", CompletionKind::Function});
    for (const BuiltinConstant& c : builtinConstants())
        names.push_back({std::string(c.name), c.type.str(), "built-in constant", CompletionKind::Constant});
    for (std::string_view v : builtinVariables())
        names.push_back({std::string(v), "float", "built-in variable", CompletionKind::Variable});
    names.push_back({std::string(kInstanceName), "instance", "the instance the object belongs to: instance.pos, …",
                     CompletionKind::Variable});
    for (std::string_view t : Type::names()) names.push_back({std::string(t), "type", "", CompletionKind::TypeParameter});
    return names;
}

// What a fn's body may not name (the checker's errors there).
bool impure(const Name& n) {
    if (n.kind == CompletionKind::Class || n.kind == CompletionKind::Event) return true;
    if (n.detail.starts_with("extern ")) return true;
    if (n.label == kInstanceName && n.detail == "instance") return true;
    if (n.kind == CompletionKind::Variable && isBuiltinVariable(n.label) && n.documentation == "built-in variable") return true;
    int f = n.kind == CompletionKind::Function ? findBuiltinFunction(n.label) : -1;
    return f >= 0 && n.documentation == "built-in function" && isTemporal(builtinFunction(f).rule);
}

// A vector's components and its common swizzles, for a value of `width` components.
std::vector<Name> swizzles(int width) {
    static const char* xyzw = "xyzw";
    static const char* rgba = "rgba";
    std::vector<Name> names;
    auto add = [&](std::string s) { names.push_back({s, "swizzle", "", CompletionKind::Field}); };
    for (int i = 0; i < width; ++i) add(std::string(1, xyzw[i]));
    for (int i = 0; i < width; ++i) add(std::string(1, rgba[i]));
    add("xy");
    if (width >= 3) add("xz"), add("yz"), add("xyz"), add("rgb");
    return names;
}

// The width of a vector a name in scope at `offset` holds (its detail ends in `: vecN`), or 0.
int vectorWidth(const Analysis& a, const std::string& name, uint32_t offset) {
    auto width = [](const Name& n) {
        size_t colon = n.detail.rfind(": ");
        std::string t = colon == std::string::npos ? n.detail : n.detail.substr(colon + 2);
        return t == "vec2" ? 2 : t == "vec3" || t == "color" || t == "point" ? 3 : t == "vec4" ? 4 : 0;
    };
    for (const Scope& s : a.scopes)
        if (s.range.file == a.mainFile && s.range.begin <= offset && offset <= s.range.end)
            for (const Name& n : s.names)
                if (n.label == name) return width(n);
    for (const Name& n : a.globals)
        if (n.label == name) return width(n);
    for (const BuiltinConstant& c : builtinConstants())
        if (c.name == name) return c.type.width() > 1 ? c.type.width() : 0;
    return 0;
}

// The main file's objects whose declaration holds `offset`, outermost first (the last is
// the one the cursor is in).
std::vector<std::string> objectsAround(const Analysis& a, uint32_t offset) {
    std::vector<std::string> path;
    const std::vector<Symbol>* level = &a.symbols;
    for (bool deeper = true; deeper;) {
        deeper = false;
        for (const Symbol& s : *level)
            if (s.kind == SymbolKind::Class && s.range.begin < offset && offset < s.range.end) {
                path.push_back(s.name);
                level = &s.children;
                deeper = true;
                break;
            }
    }
    return path;
}

// Keywords that begin a declaration of the file: not written inside an object or a fn.
bool topLevelOnly(std::string_view k) {
    return k == "import" || k == "const" || k == "fn" || k == "extern" || k == "range" || k == "trigger" || k == "spawn";
}

// What a fn's body is made of: lets and one expression.
bool inFnBody(std::string_view k) { return k == "let" || k == "if" || k == "then" || k == "else" || k == "true" || k == "false"; }

// The text before `offset` without trailing blanks.
std::string_view before(const std::string& text, size_t offset) {
    while (offset > 0 && (text[offset - 1] == ' ' || text[offset - 1] == '\t')) --offset;
    return std::string_view(text).substr(0, offset);
}

}  // namespace

nlohmann::json vocabulary() {
    nlohmann::json v;
    auto list = [](auto&& names) {
        nlohmann::json out = nlohmann::json::array();
        for (const auto& n : names) out.push_back(std::string(n));
        return out;
    };
    v["keywords"] = list(keywords());
    v["functions"] = nlohmann::json::array();
    for (const BuiltinFunction& f : builtinFunctions()) v["functions"].push_back(std::string(f.name));
    v["constants"] = nlohmann::json::array();
    for (const BuiltinConstant& c : builtinConstants()) v["constants"].push_back(std::string(c.name));
    v["variables"] = list(builtinVariables());
    v["types"] = list(Type::names());
    v["attributes"] = nlohmann::json::array();
    for (const BuiltinAttribute& a : builtinAttributes()) v["attributes"].push_back(std::string(a.name));
    v["integrators"] = list(integratorNames());
    return v;
}

nlohmann::json completion(const Analysis& a, const std::string& text, uint32_t offset) {
    size_t end = std::min<size_t>(offset, text.size()), start = end;
    while (start > 0 && identChar(text[start - 1])) --start;
    std::vector<Name> names;
    std::string_view lead = before(text, start);
    if (start > 0 && text[start - 1] == '.') {
        size_t baseStart = start - 1;
        while (baseStart > 0 && identChar(text[baseStart - 1])) --baseStart;
        std::string base = text.substr(baseStart, start - 1 - baseStart);
        // An object's members are read live only from inside its children: `rocket.`
        // offers rocket's where the cursor is in an object rocket encloses.
        std::vector<std::string> around = objectsAround(a, offset);
        if (!around.empty()) around.pop_back();  // (the object the cursor is in is not its own parent)
        if (std::find(around.begin(), around.end(), base) != around.end())
            for (const auto& [object, members] : a.members)
                if (object == base) names = members;
        if (names.empty() && base == kInstanceName)  // the instance an object belongs to
            for (const InstanceMember& m : instanceMembers())
                names.push_back({std::string(m.name), m.width == 1 ? "float" : "vec3", std::string(m.meaning),
                                 CompletionKind::Field});
        if (names.empty())
            if (int width = a.parsed ? vectorWidth(a, base, offset) : 0) names = swizzles(width);
    } else if (start > 0 && text[start - 1] == '@') {
        for (const BuiltinAttribute& at : builtinAttributes())
            names.push_back({std::string(at.name), std::string(at.signature), std::string(at.doc), CompletionKind::Property});
    } else if (lead.size() >= 1 && lead.back() == '(' && before(text, lead.size() - 1).ends_with("@integrator")) {
        for (std::string_view m : integratorNames()) names.push_back({std::string(m), "integrator", "", CompletionKind::Constant});
    } else if (lead.size() >= 1 && lead.back() == '(' && before(text, lead.size() - 1).ends_with("@precision")) {
        names.push_back({"float", "precision", "state as floats (the default)", CompletionKind::Constant});
        names.push_back({"double", "precision", "state as pairs of floats, 48 significant bits", CompletionKind::Constant});
    } else {
        bool pure = false;
        if (a.parsed)
            for (const Scope& s : a.scopes)
                if (s.range.file == a.mainFile && s.range.begin <= offset && offset <= s.range.end) {
                    names.insert(names.end(), s.names.begin(), s.names.end());
                    pure |= s.pure;
                }
        names.insert(names.end(), a.globals.begin(), a.globals.end());
        std::vector<Name> builtins = builtinNames();
        names.insert(names.end(), builtins.begin(), builtins.end());
        if (pure) std::erase_if(names, impure);
        // Keywords where they can be written: a declaration's only at the top of the file,
        // a fn's body only lets and conditionals, an object's no `let`.
        bool inObject = a.parsed && !objectsAround(a, offset).empty();
        std::erase_if(names, [&](const Name& n) {
            if (n.kind != CompletionKind::Keyword) return false;
            if (pure) return !inFnBody(n.label);
            return inObject && (topLevelOnly(n.label) || n.label == "let");
        });
    }
    nlohmann::json items = nlohmann::json::array();
    std::set<std::string> seen;  // the innermost declaration of a name wins
    for (const Name& n : names)
        if (seen.insert(n.label).second) items.push_back(item(n));
    return {{"isIncomplete", false}, {"items", items}};
}

}  // namespace psys::lsp
