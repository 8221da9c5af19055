// Scopes and name lookup.
//
// Scopes, innermost first: a fn's lets and parameters, or an object's parameters and
// equations; then the file scope (constants, externs, functions, objects and triggers of
// the main file and of everything it imports, one namespace); then the built-ins. An
// enclosing object's equations are not in scope by their bare names: a child reads them
// live and explicitly, as `rocket.pos`.
#include <algorithm>
#include <functional>

#include <fmt/format.h>

#include "frontend/builtins.h"
#include "frontend/checker.h"
#include "frontend/loader.h"

namespace psys::detail {

using namespace ast;

namespace {

const char* declWord(DeclKind kind) {
    switch (kind) {
        case DeclKind::Const: return "a constant";
        case DeclKind::Fn: return "a function";
        case DeclKind::Extern: return "an extern";
        case DeclKind::Trigger: return "a trigger";
        case DeclKind::Object: return "an object";
        default: return "a declaration";
    }
}

// Edits to turn `a` into `b`: insertions, deletions, substitutions and swaps of
// neighbours (the commonest typo), each costing one.
size_t editDistance(const std::string& a, const std::string& b) {
    std::vector<std::vector<size_t>> d(a.size() + 1, std::vector<size_t>(b.size() + 1));
    for (size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
    for (size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
    for (size_t i = 1; i <= a.size(); ++i)
        for (size_t j = 1; j <= b.size(); ++j) {
            d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
                d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
        }
    return d[a.size()][b.size()];
}

}  // namespace

std::string closestName(const std::string& name, const std::vector<std::string>& candidates) {
    std::string best;
    size_t bestDistance = std::max<size_t>(1, name.size() / 3) + 1;
    for (const std::string& c : candidates) {
        // The lengths' difference is a lower bound of the distance: a name far longer or
        // shorter than every candidate (a million characters) costs nothing to reject.
        size_t apart = name.size() > c.size() ? name.size() - c.size() : c.size() - name.size();
        if (apart >= bestDistance) continue;
        size_t d = editDistance(name, c);
        if (d < bestDistance) {
            bestDistance = d;
            best = c;
        }
    }
    return best;
}

namespace {

// What the language defines `name` as, where it does (the end of "`name` is …"), else null.
const char* languageDefines(const std::string& name) {
    if (name == kInstanceName) return "a built-in value (the instance an object belongs to: `instance.pos`, …)";
    if (isBuiltinVariable(name)) return "a built-in variable";
    if (findBuiltinConstant(name) >= 0) return "a built-in constant";
    if (Type::fromName(name)) return "a type";
    return nullptr;
}

}  // namespace

// A user's name may not redefine what the language defines.
bool Checker::checkDeclarableName(const std::string& name, SourceRange range, const char* what) {
    const char* is = languageDefines(name);
    if (is) diags_.error(range, fmt::format("cannot declare {} named `{}`: `{}` is {}", what, name, name, is));
    return is == nullptr;
}

void Checker::declareGlobal(Decl& decl) {
    if (findBuiltinFunction(decl.name) >= 0) {
        diags_.error(decl.nameRange, fmt::format("cannot declare {} named `{}`: `{}` is a built-in function",
                                                 declWord(decl.kind), decl.name, decl.name));
        return;
    }
    if (!checkDeclarableName(decl.name, decl.nameRange, declWord(decl.kind))) return;
    auto [it, inserted] = globals_.emplace(decl.name, &decl);
    if (!inserted) {
        diags_.error(decl.nameRange, fmt::format("redefinition of `{}`", decl.name))
            .notes.push_back({it->second->nameRange,
                              fmt::format("`{}` was first declared here as {}", decl.name, declWord(it->second->kind))});
    }
}

void Checker::collectGlobals() {
    std::function<void(const ObjectDecl&)> collectNested = [&](const ObjectDecl& object) {
        std::map<std::string, const ObjectDecl*> siblings;
        for (auto& child : object.children) {
            nestedObjects_.emplace(child->name, child.get());
            auto [it, inserted] = siblings.emplace(child->name, child.get());
            if (!inserted)
                diags_.error(child->nameRange, fmt::format("redefinition of object `{}` inside `{}`", child->name, object.name))
                    .notes.push_back({it->second->nameRange, "first declared here"});
            collectNested(*child);
        }
    };
    for (auto& module : program_.modules) {
        for (auto& decl : module->decls) {
            switch (decl->kind) {
                case DeclKind::Const: case DeclKind::Fn: case DeclKind::Extern: case DeclKind::Trigger:
                    declareGlobal(*decl);
                    break;
                case DeclKind::Object:
                    declareGlobal(*decl);
                    collectNested(static_cast<ObjectDecl&>(*decl));
                    break;
                default: break;
            }
        }
    }
}

std::vector<std::string> Checker::globalNames(std::initializer_list<DeclKind> kinds) const {
    if (!everyGlobal_) {
        everyGlobal_.emplace();
        for (const auto& [name, decl] : globals_) everyGlobal_->emplace(name, decl->kind);
        // (As declareGlobal would: the first of a name, none the language defines.)
        for (const auto& [name, kind] : options_.declaredElsewhere)
            if (findBuiltinFunction(name) < 0 && languageDefines(name) == nullptr) everyGlobal_->emplace(name, kind);
    }
    std::vector<std::string> out;
    for (const auto& [name, kind] : *everyGlobal_)
        if (std::find(kinds.begin(), kinds.end(), kind) != kinds.end()) out.push_back(name);
    return out;
}

std::vector<std::string> Checker::nestedNames() const {
    std::vector<std::string> out;
    for (const auto& [name, object] : nestedObjects_) out.push_back(name);
    out.insert(out.end(), options_.nestedElsewhere.begin(), options_.nestedElsewhere.end());
    std::stable_sort(out.begin(), out.end());
    return out;
}

// The enclosing object called `name`, if any, and how many levels up it is.
const ObjectDecl* Checker::enclosingObject(const std::string& name, const Context& ctx, int* depth) const {
    if (ctx.where != Where::Object || !ctx.object) return nullptr;
    int level = 0;
    for (const ObjectDecl* p = ctx.object->parent; p; p = p->parent) {
        ++level;
        if (p->name == name) {
            *depth = level;
            return p;
        }
    }
    return nullptr;
}

std::vector<std::string> Checker::namesInScope(const Context& ctx) const {
    std::vector<std::string> names;
    if (ctx.where == Where::Object && ctx.object) {
        auto it = objectScopes_.find(ctx.object);
        if (it != objectScopes_.end())
            for (auto& [n, _] : it->second.names) names.push_back(n);
        for (std::string_view v : builtinVariables()) names.emplace_back(v);
    }
    if (ctx.fn) {
        for (auto& p : ctx.fn->params) names.push_back(p.name);
        for (size_t i = 0; i < ctx.letsVisible; ++i) names.push_back(ctx.fn->lets[i]->name);
    }
    if (ctx.trigger)
        for (auto& p : ctx.trigger->params) names.push_back(p.name);
    for (std::string& n : globalNames({DeclKind::Const, DeclKind::Extern})) names.push_back(std::move(n));
    for (auto& c : builtinConstants()) names.emplace_back(c.name);
    return names;
}

void Checker::reportUnknown(const std::string& what, const std::string& name, SourceRange range,
                            const std::function<std::vector<std::string>()>& candidates) {
    // A suggestion costs a search of the names in scope: none for errors no one will see.
    bool shown = diags_.errorCount() < diags_.limit() && !diags_.suppressed();
    if (!shown) {
        diags_.error(range, fmt::format("unknown {} `{}`", what, name));
        return;
    }
    // A name of the standard library's that the file does not import.
    if (std::string library = libraryFileDeclaring(name); !library.empty()) {
        diags_.error(range, fmt::format("unknown {} `{}`; the standard library declares it in {}: add "
                                        "`import \"{}\";`", what, name, library, library))
            .fixes.push_back({fmt::format("Import \"{}\"", library), importPoint(range.file),
                              fmt::format("import \"{}\";\n", library)});
        return;
    }
    std::string suggestion = closestName(name, candidates());
    if (suggestion.empty()) {
        diags_.error(range, fmt::format("unknown {} `{}`", what, name));
        return;
    }
    diags_.error(range, fmt::format("unknown {} `{}`; did you mean `{}`?", what, name, suggestion))
        .fixes.push_back({fmt::format("Change to `{}`", suggestion), range, suggestion});
}

SourceRange Checker::importPoint(int file) const {
    const ast::Module* module = nullptr;
    for (const auto& m : program_.modules)
        if (m->file == file) module = m.get();
    if (!module) return {file, 0, 0};
    const SourceFile& text = diags_.sources().file(file);
    uint32_t at = 0;
    for (const auto& decl : module->decls)
        if (decl->kind == ast::DeclKind::Import) at = decl->range.end;
    if (at == 0 && !module->decls.empty()) at = module->decls.front()->range.begin;
    else if (at > 0) at = text.offset({text.lineColumn(at).line + 1, 1});  // the line after the last import
    return {file, at, at};
}

Ref Checker::lookupName(const std::string& name, SourceRange range, const Context& ctx) {
    Ref ref;
    // Inner scopes: fn lets and parameters, trigger parameters, the object's own names.
    if (ctx.fn) {
        for (size_t i = ctx.letsVisible; i-- > 0;) {
            if (ctx.fn->lets[i]->name == name) {
                ref.kind = Ref::Kind::Let;
                ref.let = ctx.fn->lets[i].get();
                return ref;
            }
        }
        for (size_t i = 0; i < ctx.fn->params.size(); ++i) {
            if (ctx.fn->params[i].name == name) {
                ref.kind = Ref::Kind::FnParam;
                ref.fn = ctx.fn;
                ref.index = static_cast<int>(i);
                return ref;
            }
        }
    }
    if (ctx.trigger) {
        for (size_t i = 0; i < ctx.trigger->params.size(); ++i) {
            if (ctx.trigger->params[i].name == name) {
                ref.kind = Ref::Kind::TriggerParam;
                ref.trigger = ctx.trigger;
                ref.index = static_cast<int>(i);
                return ref;
            }
        }
    }
    if (name == kInstanceName) {
        std::string members;
        for (const InstanceMember& m : instanceMembers()) members += fmt::format("{}`instance.{}`", members.empty() ? "" : ", ", m.name);
        diags_.error(range, fmt::format("`instance` is read by its members: {}", members));
        return ref;
    }
    if (isBuiltinVariable(name)) {
        bool allowed = ctx.where == Where::Object || (name == "time" && (ctx.where == Where::Trigger || ctx.where == Where::Spawn));
        if (!allowed) {
            const char* place = ctx.where == Where::Fn ? "a function: functions are pure; pass it as a parameter"
                                : ctx.where == Where::Trigger ? "a trigger: a trigger has no age or step of its own"
                                : ctx.where == Where::Spawn ? "a spawn: nothing has aged yet"
                                : "a constant expression";
            diags_.error(range, fmt::format("`{}` cannot be used in {}", name, place));
            return ref;
        }
        ref.kind = name == "age" ? Ref::Kind::Age : name == "time" ? Ref::Kind::Time : Ref::Kind::Dt;
        return ref;
    }
    if (ctx.where == Where::Object && ctx.object) {
        auto& scope = objectScopes_[ctx.object];
        if (auto it = scope.names.find(name); it != scope.names.end()) return it->second;
        for (const ObjectDecl* p = ctx.object->parent; p; p = p->parent) {
            auto& outer = objectScopes_[p];
            if (auto it = outer.names.find(name); it != outer.names.end()) {
                diags_.error(range, fmt::format("`{}` belongs to the enclosing object `{}`; read it live as `{}.{}`",
                                                name, p->name, p->name, name))
                    .notes.push_back({outer.declaredAt[name], fmt::format("`{}` is declared here", name)});
                return ref;
            }
        }
    }
    // File scope.
    if (auto it = globals_.find(name); it != globals_.end()) {
        Decl* decl = it->second;
        switch (decl->kind) {
            case DeclKind::Const:
                ref.kind = Ref::Kind::Const;
                ref.constant = static_cast<ConstDecl*>(decl);
                checkConst(*static_cast<ConstDecl*>(decl));
                return ref;
            case DeclKind::Extern:
                if (ctx.where == Where::Fn || ctx.where == Where::Const || ctx.where == Where::ExternValue ||
                    ctx.where == Where::Attribute) {
                    const char* place = ctx.where == Where::Fn ? "a function: functions are pure; pass it as a parameter"
                                                               : "a constant expression: externs change while the system runs";
                    diags_.error(range, fmt::format("extern `{}` cannot be used in {}", name, place))
                        .notes.push_back({decl->nameRange, "declared here"});
                    return ref;
                }
                ref.kind = Ref::Kind::Extern;
                ref.externVar = static_cast<ExternDecl*>(decl);
                return ref;
            case DeclKind::Fn:
                diags_.error(range, fmt::format("`{}` is a function; call it with arguments: `{}(…)`", name, name))
                    .notes.push_back({decl->nameRange, "declared here"});
                return ref;
            case DeclKind::Object:
                diags_.error(range, fmt::format("`{}` is an object type, not a value; create one with `emit {}(…)`", name, name))
                    .notes.push_back({decl->nameRange, "declared here"});
                return ref;
            case DeclKind::Trigger:
                diags_.error(range, fmt::format("`{}` is a trigger, not a value; the host fires it", name))
                    .notes.push_back({decl->nameRange, "declared here"});
                return ref;
            default: break;
        }
    }
    if (int c = findBuiltinConstant(name); c >= 0) {
        ref.kind = Ref::Kind::BuiltinConst;
        ref.index = c;
        return ref;
    }
    if (findBuiltinFunction(name) >= 0) {
        diags_.error(range, fmt::format("`{}` is a built-in function; call it with arguments: `{}(…)`", name, name));
        return ref;
    }
    reportUnknown("name", name, range, [&] { return namesInScope(ctx); });
    return ref;
}

const ObjectDecl* Checker::findEmitTarget(const std::string& name, SourceRange range, const Context& ctx) {
    if (ctx.where == Where::Object && ctx.object)
        for (auto& child : ctx.object->children)
            if (child->name == name) return child.get();
    if (auto it = globals_.find(name); it != globals_.end()) {
        if (it->second->kind == DeclKind::Object) return static_cast<const ObjectDecl*>(it->second);
        diags_.error(range, fmt::format("`{}` is {}, not an object", name, declWord(it->second->kind)))
            .notes.push_back({it->second->nameRange, "declared here"});
        return nullptr;
    }
    auto nested = nestedObjects_.find(name);
    if (nested != nestedObjects_.end()) {
        const ObjectDecl* parent = nested->second->parent;
        diags_.error(range, fmt::format("`{}` is declared inside `{}`; only `{}` can create it, since it reads its parent",
                                        name, parent->name, parent->name))
            .notes.push_back({nested->second->nameRange, "declared here"});
        return nullptr;
    }
    reportUnknown("object", name, range, [&] {
        std::vector<std::string> candidates = globalNames({DeclKind::Object});
        if (ctx.where == Where::Object && ctx.object)
            for (auto& child : ctx.object->children) candidates.push_back(child->name);
        return candidates;
    });
    return nullptr;
}

}  // namespace psys::detail
