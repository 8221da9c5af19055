// Checking the neighbour folds: `near_count(T, r)`, `near_sum(T, r, term)`, `near_min`,
// `near_max` (docs/language.md, "Neighbours").
//
// A fold is over the objects of type T whose drawn position lies within `r` of this
// object's, at the start of the step. Its term is computed once per pair from the two
// objects' values as they were then, so it may read this object's equations and
// parameters, `other.NAME` (the neighbour's), constants and externs — nothing with a
// history of its own (age, prev, integrate, rand: a term is no equation of either
// object) and nothing of a function's or an enclosing object's.
#include <cmath>

#include <fmt/format.h>

#include <set>

#include "core/fold.h"
#include "frontend/builtins.h"
#include "frontend/checker.h"
#include "frontend/consteval.h"

namespace psys::detail {

using namespace ast;

const ObjectDecl* Checker::findObjectType(const std::string& name) const {
    if (auto it = globals_.find(name); it != globals_.end() && it->second->kind == DeclKind::Object)
        return static_cast<const ObjectDecl*>(it->second);
    auto [first, last] = nestedObjects_.equal_range(name);
    if (first != last && std::next(first) == last) return first->second;
    return nullptr;
}

Type Checker::checkNear(CallExpr& call, const Context& ctx) {
    core::Reduce reduce = *core::neighbourFold(call.callee);
    const core::ReduceInfo& info = core::reduceInfo(reduce);
    std::string usage = info.term ? fmt::format("`{}(type, radius, term)`", call.callee)
                                  : fmt::format("`{}(type, radius)`", call.callee);
    if (ctx.where != Where::Object || !ctx.object) {
        diags_.error(call.calleeRange, fmt::format("`{}` can be used only in an object's equations: it folds over the "
                                                   "objects near this one", call.callee));
        return Type::error();
    }
    if (ctx.fold) {
        diags_.error(call.calleeRange, fmt::format("`{}` cannot be used in the term of `{}`", call.callee, ctx.fold->callee));
        return Type::error();
    }
    size_t want = info.term ? 3 : 2;
    if (call.args.size() != want) {
        diags_.error(call.range, fmt::format("`{}` takes {} arguments, but {} {} given: {}", call.callee, want,
                                             call.args.size(), call.args.size() == 1 ? "was" : "were", usage));
        return Type::error();
    }
    // The type folded over: a name, not a value.
    const Expr& typeArg = *call.args[0];
    const ObjectDecl* target = nullptr;
    if (typeArg.kind == ExprKind::Name) target = findObjectType(static_cast<const NameExpr&>(typeArg).name);
    if (!target) {
        std::string suggestion;
        if (typeArg.kind == ExprKind::Name) {
            const std::string& named = static_cast<const NameExpr&>(typeArg).name;
            if (nestedObjects_.count(named) > 1) {
                Diagnostic& d = diags_.error(typeArg.range, fmt::format("`{}` names {} nested object types: a fold "
                                                                        "folds over one (rename one of them)",
                                                                        named, nestedObjects_.count(named)));
                auto [first, last] = nestedObjects_.equal_range(named);
                for (auto it = first; it != last; ++it) d.notes.push_back({it->second->nameRange, "declared here"});
                return Type::error();
            }
            std::vector<std::string> types;
            for (std::string& name : globalNames({DeclKind::Object}))
                if (name != named) types.push_back(std::move(name));
            for (std::string& name : nestedNames())
                if (name != named) types.push_back(std::move(name));
            suggestion = closestName(named, types);
        }
        Diagnostic& d = diags_.error(typeArg.range, fmt::format("the first argument of `{}` must name an object type (the "
                                                                "objects it folds over): {}{}", call.callee, usage,
                                                                suggestion.empty() ? "" : fmt::format("; did you mean `{}`?", suggestion)));
        if (!suggestion.empty()) d.fixes.push_back({fmt::format("Change to `{}`", suggestion), typeArg.range, suggestion});
        return Type::error();
    }
    call.neighbours = target;
    // The radius: the grid's cell, fixed for the program.
    check(*call.args[1], ctx);
    // From 1e-18 to 1e18: a distance within it squared is a normal float (the terms compare
    // d² with r²); past them r² rounded to 0 or infinity, and a fold counted objects far
    // outside its radius, differently for each of two objects.
    constexpr double kLeast = 1e-18, kMost = 1e18;
    auto r = evaluateConstant(*call.args[1]);
    std::string why = !r                      ? "it is not a constant"
                      : !r->type.isFloat()    ? "it is a " + r->type.str()
                      : std::isnan(r->v[0])   ? "it is not a number (NaN)"
                      : !(r->v[0] >= kLeast) || !(r->v[0] <= kMost) ? fmt::format("it is {:g}", r->v[0])
                                              : "";
    if (!why.empty()) {
        diags_.error(call.args[1]->range, fmt::format("the radius of `{}` must be a constant number from 1e-18 to 1e18 "
                                                      "(the objects within it are folded over); {}", call.callee, why));
        return Type::error();
    }
    call.radius = r->v[0];
    if (!info.term) return Type::scalar();
    Context inner = ctx;
    inner.fold = &call;
    inner.other = target;
    Type t = check(*call.args[2], inner);
    if (t.isVague()) return t;
    if (!t.isNumeric()) {
        diags_.error(call.args[2]->range, fmt::format("the term of `{}` must be a number or vector, found {}",
                                                      call.callee, t.str()));
        return Type::error();
    }
    return t;
}

// `other.vel`: the neighbour's equation or parameter.
Type Checker::checkNeighbourMember(MemberExpr& member, const Context& ctx) {
    const ObjectDecl* other = ctx.other;
    member.parent = other;
    member.neighbour = true;
    member.base->type = Type::error();  // `other` is not a value of its own
    auto found = memberOf(*other, member, {});
    if (!found) return Type::error();
    member.parentRef = *found;
    return typeOfRef(member.parentRef);
}

namespace {

// Whether evaluating `e` draws a random number (through the functions it calls too).
bool draws(const Expr& e, std::set<const FnDecl*>& seen);
bool draws(const FnDecl& fn, std::set<const FnDecl*>& seen) {
    if (!seen.insert(&fn).second) return false;
    if (fn.body && draws(*fn.body, seen)) return true;
    for (const auto& let : fn.lets)
        if (draws(*let->value, seen)) return true;
    return false;
}
bool draws(const Expr& e, std::set<const FnDecl*>& seen) {
    auto any = [&](std::initializer_list<const Expr*> xs) {
        for (const Expr* x : xs)
            if (x && draws(*x, seen)) return true;
        return false;
    };
    switch (e.kind) {
        case ExprKind::Call: {
            auto& c = static_cast<const CallExpr&>(e);
            if (c.builtin >= 0 && builtinFunction(c.builtin).rule == BuiltinRule::Random) return true;
            if (c.fn && draws(*c.fn, seen)) return true;
            for (const ExprPtr& a : c.args)
                if (draws(*a, seen)) return true;
            return false;
        }
        case ExprKind::Member: return any({static_cast<const MemberExpr&>(e).base.get()});
        case ExprKind::Unary: return any({static_cast<const UnaryExpr&>(e).operand.get()});
        case ExprKind::Binary: {
            auto& b = static_cast<const BinaryExpr&>(e);
            return any({b.lhs.get(), b.rhs.get()});
        }
        case ExprKind::Conditional: {
            auto& c = static_cast<const ConditionalExpr&>(e);
            return any({c.cond.get(), c.thenExpr.get(), c.elseExpr.get()});
        }
        case ExprKind::Tuple:
            for (const ExprPtr& x : static_cast<const TupleExpr&>(e).elements)
                if (draws(*x, seen)) return true;
            return false;
        case ExprKind::FollowedBy: {
            auto& f = static_cast<const FollowedByExpr&>(e);
            return any({f.init.get(), f.next.get()});
        }
        default: return false;
    }
}

}  // namespace

// A function called in a fold's term: it must not draw random numbers (a term is a
// function of the two objects, not a draw).
void Checker::checkFoldCall(const CallExpr& call, const Context& ctx) {
    std::set<const FnDecl*> seen;
    if (ctx.fold && call.fn && draws(*call.fn, seen))
        diags_.error(call.calleeRange, fmt::format("`{}` draws random numbers, so it cannot be used in the term of `{}`: "
                                                   "a term is a function of the two objects as they are",
                                                   call.callee, ctx.fold->callee))
            .notes.push_back({call.fn->nameRange, fmt::format("`{}` declared here", call.callee)});
}

// What a fold's term may read by name.
bool Checker::checkFoldTermRef(const NameExpr& name, const Context& ctx) {
    switch (name.ref.kind) {
        case Ref::Kind::Extern: foldExternReads_.emplace_back(&name, ctx.fold->callee); return true;
        case Ref::Kind::Param: case Ref::Kind::Equation: case Ref::Kind::Const:
        case Ref::Kind::BuiltinConst: case Ref::Kind::Unresolved:
            return true;
        default: break;
    }
    diags_.error(name.range, fmt::format("the term of `{}` cannot read `{}`: it may read this object's equations and "
                                         "parameters, `other.NAME`, constants and externs", ctx.fold->callee, name.name));
    return false;
}

// In an instanced program each instance has its own value of an extern, and a term is of
// two objects that may be of different instances: it reads one through an equation of
// this object (core/instances.h; the lowering keeps a term's extern reads effect-wide).
void Checker::reportInstancedFoldExterns() {
    if (!program_.instanced) return;
    std::set<const NameExpr*> said;  // (a term is checked more than once as types settle)
    for (const auto& [name, fold] : foldExternReads_)
        if (said.insert(name).second)
            diags_.error(name->range, fmt::format("the term of `{}` cannot read extern `{}` in an instanced program: each "
                                              "instance has its own, and the two objects of a term may be of two "
                                              "instances; read it through an equation of this object (`{}_here = {};`) "
                                              "and name that",
                                              fold, name->name, name->name, name->name));
}

}  // namespace psys::detail
