// Checking file-level declarations: constants, functions, externs, triggers and spawns,
// and the order in which the whole program is checked.
#include <cmath>
#include <functional>

#include <fmt/format.h>

#include "frontend/builtins.h"
#include "frontend/checker.h"
#include "frontend/consteval.h"

namespace psys::detail {

using namespace ast;

namespace {

// "a → b → a" for a cycle that closes at `again`.
std::string cyclePath(const std::vector<const Decl*>& stack, const Decl* again) {
    std::string path;
    bool inCycle = false;
    for (const Decl* d : stack) {
        inCycle |= d == again;
        if (inCycle) path += d->name + " → ";
    }
    return path + again->name;
}

}  // namespace

void Checker::checkParams(const std::vector<Param>& params, const char* owner) {
    std::map<std::string, SourceRange> seen;
    for (const Param& p : params) {
        if (p.type.type.isTuple())
            diags_.error(p.type.range, fmt::format("a parameter of {} cannot be a tuple; pass its parts separately",
                                                   owner));
        if (auto it = seen.find(p.name); it != seen.end())
            diags_.error(p.nameRange, fmt::format("parameter `{}` is declared twice", p.name))
                .notes.push_back({it->second, "first declared here"});
        seen[p.name] = p.nameRange;
    }
}

void Checker::checkConst(ConstDecl& decl) {
    int& state = progress_[&decl];
    if (state == 2) return;
    if (state == 1) {
        diags_.error(decl.nameRange, fmt::format("constant `{}` is defined in terms of itself: {}", decl.name,
                                                 cyclePath(checking_, &decl)));
        decl.type = Type::error();
        return;
    }
    state = 1;
    checking_.push_back(&decl);
    Context ctx;
    ctx.where = Where::Const;
    Type t = check(*decl.value, ctx);
    if (t.isTuple()) {
        diags_.error(decl.value->range, "a constant cannot be a tuple");
        t = Type::error();
    }
    if (decl.annotation) {
        if (!t.isVague() && t != decl.annotation->type)
            diags_.error(decl.value->range, fmt::format("constant `{}` is declared {} but its value is {}", decl.name,
                                                        decl.annotation->type.str(), t.str()))
                .notes.push_back({decl.annotation->range, "declared type"});
        t = decl.annotation->type;
    }
    if (decl.type.isUnknown()) decl.type = t;
    // As for an extern's default: a constant is a number a reader can rely on. Its value,
    // computed here, is what lowering makes of it (ConstDecl::evaluated).
    if (!t.isVague())
        if (auto v = evaluateConstant(*decl.value); v && v->type == t) {
            bool finite = true;
            for (int i = 0; i < std::max(1, t.width()) && !t.isBool() && finite; ++i)
                if (!std::isfinite(v->v[static_cast<size_t>(i)])) {
                    diags_.error(decl.value->range, fmt::format("constant `{}` is not a finite number ({})", decl.name,
                                                                numberText(v->v[static_cast<size_t>(i)])));
                    finite = false;
                }
            if (finite) decl.evaluated = v;
        }
    checking_.pop_back();
    progress_[&decl] = 2;
}

void Checker::checkFn(const FnDecl& constDecl) {
    auto& decl = const_cast<FnDecl&>(constDecl);  // the checker annotates; callers hold const views
    int& state = progress_[&decl];
    if (state == 2) return;
    if (state == 1) {
        diags_.error(decl.nameRange, fmt::format("function `{}` calls itself ({}); functions are inlined, so they "
                                                 "cannot be recursive", decl.name, cyclePath(checking_, &decl)));
        decl.resultType = Type::error();
        return;
    }
    state = 1;
    checking_.push_back(&decl);
    checkParams(decl.params, "a function");
    Context ctx;
    ctx.where = Where::Fn;
    ctx.fn = &decl;
    // One scope: the parameters and the lets; nothing in it is declared twice.
    std::map<std::string, SourceRange> declared;
    for (const Param& p : decl.params) declared.emplace(p.name, p.nameRange);
    for (size_t i = 0; i < decl.lets.size(); ++i) {
        LetStmt& let = *decl.lets[i];
        ctx.letsVisible = i;
        if (auto [it, fresh] = declared.emplace(let.name, let.nameRange); !fresh)
            diags_.error(let.nameRange, fmt::format("`{}` is already declared in function `{}`", let.name, decl.name))
                .notes.push_back({it->second, "first declared here"});
        Type t = check(*let.value, ctx);
        if (let.annotation) {
            if (!t.isVague() && t != let.annotation->type)
                diags_.error(let.value->range, fmt::format("`{}` is declared {} but its value is {}", let.name,
                                                           let.annotation->type.str(), t.str()))
                    .notes.push_back({let.annotation->range, "declared type"});
            t = let.annotation->type;
        }
        let.type = t;
    }
    ctx.letsVisible = decl.lets.size();
    Type result = check(*decl.body, ctx);
    if (decl.returnType) {
        if (!result.isVague() && result != decl.returnType->type)
            diags_.error(decl.body->range, fmt::format("function `{}` returns {}, but its body is {}", decl.name,
                                                       decl.returnType->type.str(), result.str()))
                .notes.push_back({decl.returnType->range, "declared return type"});
        result = decl.returnType->type;
    }
    if (decl.resultType.isUnknown()) decl.resultType = result;
    checking_.pop_back();
    progress_[&decl] = 2;
}

void Checker::checkExtern(ExternDecl& decl) {
    const Type& type = decl.type.type;
    if (type.isTuple()) {
        diags_.error(decl.type.range, "an extern cannot be a tuple; declare one extern per value");
        return;
    }
    Context ctx;
    ctx.where = Where::ExternValue;
    // A default or bound may be a float for a vector extern: it applies to every component.
    auto checkValue = [&](Expr& e, const char* what) -> std::optional<ConstValue> {
        Type t = check(e, ctx);
        if (t.isVague()) return std::nullopt;
        bool fits = t == type || (t.isFloat() && type.isVector());
        if (!fits) {
            diags_.error(e.range, fmt::format("the {} of extern `{}` must be {}{}, found {}", what, decl.name,
                                              type.str(), type.isVector() ? " or float" : "", t.str()))
                .notes.push_back({decl.type.range, "the extern's type"});
            return std::nullopt;
        }
        auto v = evaluateConstant(e);
        if (!v) {
            diags_.error(e.range, fmt::format("the {} of extern `{}` must be a constant", what, decl.name));
            return std::nullopt;
        }
        if (v->type.isFloat() && type.isVector()) {
            for (int i = 1; i < type.width(); ++i) v->v[static_cast<size_t>(i)] = v->v[0];
            v->type = type;
        }
        for (int i = 0; i < std::max(1, type.width()); ++i)
            if (!std::isfinite(v->v[static_cast<size_t>(i)])) {
                diags_.error(e.range, fmt::format("the {} of extern `{}` is not a finite number", what, decl.name));
                return std::nullopt;
            }
        return v;
    };
    std::optional<ConstValue> value, low, high;
    if (decl.defaultValue) value = checkValue(*decl.defaultValue, "default value");
    decl.defaultEvaluated = decl.defaultValue ? value : ConstValue{type, {}};
    if (decl.rangeLow) {
        if (type.isBool()) {
            diags_.error(SourceRange::join(decl.rangeLow->range, decl.rangeHigh->range),
                         fmt::format("extern `{}` is a bool; a range needs numbers", decl.name));
            return;
        }
        low = checkValue(*decl.rangeLow, "lower bound");
        high = checkValue(*decl.rangeHigh, "upper bound");
        decl.lowEvaluated = low;
        decl.highEvaluated = high;
    }
    if (!low || !high) return;
    for (int i = 0; i < type.width(); ++i) {
        auto c = static_cast<size_t>(i);
        if (!(low->v[c] < high->v[c])) {
            diags_.error(SourceRange::join(decl.rangeLow->range, decl.rangeHigh->range),
                         fmt::format("the range of extern `{}` is empty: the lower bound {} is not below the upper "
                                     "bound {}", decl.name, low->v[c], high->v[c]));
            return;
        }
    }
    ConstValue actual = value ? *value : ConstValue{type, {}};
    for (int i = 0; i < type.width(); ++i) {
        auto c = static_cast<size_t>(i);
        if (actual.v[c] < low->v[c] || actual.v[c] > high->v[c]) {
            SourceRange where = decl.defaultValue ? decl.defaultValue->range : decl.nameRange;
            diags_.error(where, fmt::format("the default value of extern `{}` ({}{}) is outside its range [{}, {}]",
                                            decl.name, actual.v[c], decl.defaultValue ? "" : ", the implicit zero",
                                            low->v[c], high->v[c]))
                .notes.push_back({SourceRange::join(decl.rangeLow->range, decl.rangeHigh->range), "the range"});
            return;
        }
    }
}

void Checker::checkTrigger(TriggerDecl& decl) {
    checkParams(decl.params, "a trigger");
    Context ctx;
    ctx.where = Where::Trigger;
    ctx.trigger = &decl;
    const Command* point = nullptr;
    checkCommands(decl.commands, ctx, &point);
}

void Checker::checkSpawn(SpawnDecl& decl) {
    Context ctx;
    ctx.where = Where::Spawn;
    decl.targetDecl = findEmitTarget(decl.name, decl.nameRange, ctx);
    if (!decl.targetDecl) {
        for (auto& a : decl.args) check(*a, ctx);
        return;
    }
    createdObjects_.insert(decl.targetDecl);
    SourceRange callRange = decl.args.empty() ? decl.nameRange : SourceRange::join(decl.nameRange, decl.args.back()->range);
    checkArguments(decl.args, *decl.targetDecl, callRange, ctx);
}

void Checker::reportUnused() {
    std::function<void(const ObjectDecl&)> visit = [&](const ObjectDecl& object) {
        for (auto& eq : object.equations)
            if (!usedEquations_.count(eq.get()) && !eq->isTuple())
                diags_.warning(eq->nameRanges[0], fmt::format("equation `{}` is never used", eq->names[0])).report =
                    ProgramReport::Unused;
        for (auto& child : object.children) visit(*child);
    };
    bool anySpawn = options_.spawnsElsewhere;
    for (auto& module : program_.modules)
        for (auto& decl : module->decls) anySpawn |= decl->kind == DeclKind::Spawn || decl->kind == DeclKind::Trigger;
    for (auto& module : program_.modules) {
        for (auto& decl : module->decls) {
            if (decl->kind != DeclKind::Object) continue;
            auto& object = static_cast<const ObjectDecl&>(*decl);
            visit(object);
            // Only the main file's objects: a library may declare objects its users never create.
            if (anySpawn && module.get() == program_.modules.back().get() && !createdObjects_.count(&object))
                diags_.warning(object.nameRange, fmt::format("object `{}` is never created: nothing spawns or emits it",
                                                             object.name))
                    .report = ProgramReport::Unused;
        }
    }
}

void Checker::run() {
    collectGlobals();
    // Constants and functions first: everything else may use them, and their own checks
    // must not run while object type inference holds diagnostics back.
    for (auto& module : program_.modules)
        for (auto& decl : module->decls) {
            if (decl->kind == DeclKind::Const) checkConst(static_cast<ConstDecl&>(*decl));
            if (decl->kind == DeclKind::Fn) checkFn(static_cast<FnDecl&>(*decl));
        }
    for (auto& module : program_.modules) {
        std::vector<Attribute*> fileAttributes;
        for (auto& decl : module->decls) {
            switch (decl->kind) {
                case DeclKind::Attribute:
                    fileAttributes.push_back(&static_cast<FileAttributeDecl&>(*decl).attribute);
                    break;
                case DeclKind::Extern: checkExtern(static_cast<ExternDecl&>(*decl)); break;
                default: break;
            }
        }
        checkAttributes(fileAttributes);
    }
    inferObjects();
    for (auto& module : program_.modules)
        for (auto& decl : module->decls) {
            if (decl->kind == DeclKind::Object) checkObject(static_cast<ObjectDecl&>(*decl));
            if (decl->kind == DeclKind::Trigger) checkTrigger(static_cast<TriggerDecl&>(*decl));
            if (decl->kind == DeclKind::Spawn) checkSpawn(static_cast<SpawnDecl&>(*decl));
        }
    reportInstancedFoldExterns();
    if (diags_.errorCount() == 0 || options_.allReports) checkInlinedSize();
    if (diags_.errorCount() == 0 || options_.allReports) reportUnused();
}

}  // namespace psys::detail
