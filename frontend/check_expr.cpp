// Type checking of expressions.
//
// Every expression gets a Type. Numbers are float; arithmetic works on float and vectors
// of equal width, and a float broadcasts to any width (thesis §2.2, the NOp class).
// `Unknown` appears while the types of recursive equations are being inferred, `Error`
// after a reported error: both are accepted everywhere, so one mistake gives one message.
#include <fmt/format.h>

#include "core/fold.h"
#include "frontend/builtins.h"
#include "frontend/checker.h"

namespace psys::detail {

using namespace ast;

namespace {

// The one type two expressions of the same value have, where what is known of each (a
// tuple may be known element by element: `(vec3(1), 2) -> prev((p, q))` while p and q are
// being inferred) agrees; nullopt where it does not.
std::optional<Type> unify(const Type& a, const Type& b) {
    if (a.isUnknown()) return b;
    if (b.isUnknown()) return a;
    if (a.isTuple() && b.isTuple() && a.elements().size() == b.elements().size()) {
        std::vector<Type> elements;
        for (size_t i = 0; i < a.elements().size(); ++i) {
            auto e = unify(a.elements()[i], b.elements()[i]);
            if (!e) return std::nullopt;
            elements.push_back(*e);
        }
        return Type::tuple(std::move(elements));
    }
    if (a == b) return a;
    return std::nullopt;
}

const char* verb(BinaryOp op) {
    switch (op) {
        case BinaryOp::Add: return "add";
        case BinaryOp::Sub: return "subtract";
        case BinaryOp::Mul: return "multiply";
        case BinaryOp::Div: return "divide";
        case BinaryOp::Mod: return "take the remainder of";
        default: return "compare";
    }
}

const char* placeWords(Where where) {
    switch (where) {
        case Where::Fn: return "a function";
        case Where::Const: return "a constant";
        case Where::ExternValue: return "an extern's default or range";
        case Where::Trigger: return "a trigger";
        case Where::Spawn: return "a spawn";
        case Where::Attribute: return "an attribute";
        case Where::Object: return "an object";
    }
    return "here";
}

// Broadcasting: equal widths, or one side a float. Unknown stays unknown unless the
// other side fixes the width.
Type broadcast(const Type& a, const Type& b) {
    if (a.isError() || b.isError()) return Type::error();
    if (a.isUnknown()) return b.isVector() ? b : Type::unknown();
    if (b.isUnknown()) return a.isVector() ? a : Type::unknown();
    if (a.width() == b.width()) return a;
    if (a.width() == 1) return b;
    if (b.width() == 1) return a;
    return Type::error();
}

}  // namespace

bool Checker::expectType(const Expr& expr, const Type& want, const std::string& what) {
    if (expr.type.isVague() || want.isVague() || expr.type == want) return true;
    diags_.error(expr.range, fmt::format("{} must be {}, found {}", what, want.str(), expr.type.str()));
    return false;
}

Type Checker::typeOfRef(const Ref& ref) {
    switch (ref.kind) {
        case Ref::Kind::Param: return ref.object->params[static_cast<size_t>(ref.index)].type.type;
        case Ref::Kind::Equation: {
            const auto& types = ref.equation->types;
            return static_cast<size_t>(ref.index) < types.size() ? types[static_cast<size_t>(ref.index)] : Type::unknown();
        }
        case Ref::Kind::Const: return ref.constant->type;
        case Ref::Kind::Extern: return ref.externVar->type.type;
        case Ref::Kind::FnParam: return ref.fn->params[static_cast<size_t>(ref.index)].type.type;
        case Ref::Kind::Let: return ref.let->type;
        case Ref::Kind::TriggerParam: return ref.trigger->params[static_cast<size_t>(ref.index)].type.type;
        case Ref::Kind::Age: case Ref::Kind::Time: case Ref::Kind::Dt: return Type::scalar();
        case Ref::Kind::Alive: return Type::boolean();
        case Ref::Kind::BuiltinConst: return builtinConstants()[static_cast<size_t>(ref.index)].type;
        case Ref::Kind::Unresolved: return Type::error();
    }
    return Type::error();
}

Type Checker::check(Expr& expr, const Context& ctx) {
    Type t;
    switch (expr.kind) {
        case ExprKind::Number: t = Type::scalar(); break;
        case ExprKind::Bool: t = Type::boolean(); break;
        case ExprKind::Name: t = checkName(static_cast<NameExpr&>(expr), ctx); break;
        case ExprKind::Call: t = checkCall(static_cast<CallExpr&>(expr), ctx); break;
        case ExprKind::Member: t = checkMember(static_cast<MemberExpr&>(expr), ctx); break;
        case ExprKind::Unary: t = checkUnary(static_cast<UnaryExpr&>(expr), ctx); break;
        case ExprKind::Binary: t = checkBinary(static_cast<BinaryExpr&>(expr), ctx); break;
        case ExprKind::Conditional: {
            auto& c = static_cast<ConditionalExpr&>(expr);
            Type cond = check(*c.cond, ctx);
            Type a = check(*c.thenExpr, ctx);
            Type b = check(*c.elseExpr, ctx);
            if (!cond.isVague() && !cond.isBool())
                diags_.error(c.cond->range, fmt::format("a condition must be bool, found {}", cond.str()));
            if (a.isError() || b.isError()) t = Type::error();
            else if (a.isUnknown()) t = b;
            else if (b.isUnknown() || a == b) t = a;
            else {
                diags_.error(expr.range, fmt::format("the two branches have different types: {} and {}", a.str(), b.str()))
                    .notes.push_back({c.elseExpr->range, fmt::format("this branch is {}", b.str())});
                t = Type::error();
            }
            break;
        }
        case ExprKind::Tuple: {
            auto& tuple = static_cast<TupleExpr&>(expr);
            std::vector<Type> elements;
            bool vague = false;
            for (auto& e : tuple.elements) {
                Type et = check(*e, ctx);
                if (et.isTuple()) {
                    diags_.error(e->range, "tuples cannot be nested");
                    et = Type::error();
                }
                vague |= et.isError();
                elements.push_back(et);
            }
            t = vague ? Type::error() : Type::tuple(std::move(elements));
            break;
        }
        case ExprKind::FollowedBy: {
            auto& f = static_cast<FollowedByExpr&>(expr);
            Type init = check(*f.init, ctx);
            Type next = check(*f.next, ctx);
            if (ctx.where != Where::Object) {
                diags_.error(expr.range, fmt::format("`->` (initial value, then next) cannot be used in {}: only object "
                                                     "equations have a history", placeWords(ctx.where)));
                t = Type::error();
            } else if (ctx.fold) {
                diags_.error(expr.range, fmt::format("`->` (initial value, then next) cannot be used in the term of `{}`: "
                                                     "a term is a function of the two objects as they are", ctx.fold->callee));
                t = Type::error();
            } else if (init.isError() || next.isError()) t = Type::error();
            else if (auto both = unify(init, next)) t = *both;
            else {
                diags_.error(expr.range, fmt::format("the initial value is {} but the next value is {}", init.str(), next.str()))
                    .notes.push_back({f.init->range, fmt::format("initial value: {}", init.str())});
                t = Type::error();
            }
            break;
        }
    }
    expr.type = t;
    return t;
}

Type Checker::checkName(NameExpr& name, const Context& ctx) {
    name.ref = lookupName(name.name, name.range, ctx);
    if (ctx.fold && !checkFoldTermRef(name, ctx)) return Type::error();
    if (name.ref.kind == Ref::Kind::Equation) usedEquations_.insert(name.ref.equation);
    return typeOfRef(name.ref);
}

Type Checker::checkUnary(UnaryExpr& unary, const Context& ctx) {
    Type t = check(*unary.operand, ctx);
    if (t.isVague()) return t;
    if (unary.op == UnaryOp::Not) {
        if (t.isBool()) return t;
        diags_.error(unary.range, fmt::format("`!` needs a bool, found {}", t.str()));
        return Type::error();
    }
    if (t.isNumeric()) return t;
    diags_.error(unary.range, fmt::format("`{}` needs a number or vector, found {}", spelling(unary.op), t.str()));
    return Type::error();
}

Type Checker::checkBinary(BinaryExpr& binary, const Context& ctx) {
    Type a = check(*binary.lhs, ctx);
    Type b = check(*binary.rhs, ctx);
    auto fail = [&](std::string message) {
        // The operands that disagree, the caret on the operator (`~~~~^~~~`).
        Diagnostic& d = diags_.error(binary.range, std::move(message));  // which names both types
        d.focus = binary.opRange.begin;
        return Type::error();
    };
    switch (binary.op) {
        case BinaryOp::Add: case BinaryOp::Sub: case BinaryOp::Mul: case BinaryOp::Div: case BinaryOp::Mod: {
            if ((!a.isVague() && !a.isNumeric()) || (!b.isVague() && !b.isNumeric()))
                return fail(fmt::format("cannot {} {} and {}: arithmetic needs numbers or vectors", verb(binary.op),
                                        a.str(), b.str()));
            Type t = broadcast(a, b);
            if (t.isError() && !a.isError() && !b.isError())
                return fail(fmt::format("cannot {} {} and {}: vectors of different sizes", verb(binary.op), a.str(),
                                        b.str()));
            return t;
        }
        case BinaryOp::Lt: case BinaryOp::Le: case BinaryOp::Gt: case BinaryOp::Ge:
            if ((!a.isVague() && !a.isFloat()) || (!b.isVague() && !b.isFloat()))
                return fail(fmt::format("`{}` compares floats, not {} and {}; compare components (`v.y < 0`) or "
                                        "lengths (`length(v) < 1`)", spelling(binary.op), a.str(), b.str()));
            return Type::boolean();
        case BinaryOp::Eq: case BinaryOp::Ne:
            if (a.isVague() || b.isVague()) return Type::boolean();
            if (a.isTuple() || b.isTuple() || a != b)
                return fail(fmt::format("cannot compare {} with {}", a.str(), b.str()));
            return Type::boolean();
        case BinaryOp::And: case BinaryOp::Or:
            if ((!a.isVague() && !a.isBool()) || (!b.isVague() && !b.isBool()))
                return fail(fmt::format("`{}` needs bool operands, not {} and {}", spelling(binary.op), a.str(), b.str()));
            return Type::boolean();
    }
    return Type::error();
}

std::optional<Ref> Checker::memberOf(const ObjectDecl& object, const MemberExpr& member,
                                     std::vector<std::string> alsoNamed) {
    auto& scope = objectScopes_[&object];
    auto it = scope.names.find(member.member);
    if (it == scope.names.end()) {
        for (auto& [n, _] : scope.names) alsoNamed.push_back(n);
        std::string suggestion = closestName(member.member, alsoNamed);
        Diagnostic& d = diags_.error(member.memberRange,
                                     fmt::format("`{}` has no equation or parameter named `{}`{}", object.name,
                                                 member.member,
                                                 suggestion.empty() ? "" : fmt::format("; did you mean `{}`?", suggestion)));
        d.notes.push_back({object.nameRange, fmt::format("`{}` declared here", object.name)});
        if (!suggestion.empty())
            d.fixes.push_back({fmt::format("Change to `{}`", suggestion), member.memberRange, suggestion});
        return std::nullopt;
    }
    if (it->second.kind == Ref::Kind::Equation) usedEquations_.insert(it->second.equation);
    return it->second;
}

// `instance.pos`: the instance the object belongs to (core/instances.h), read live in an
// object, at the start of the instance in a spawn, where fired in a trigger.
Type Checker::checkInstanceMember(MemberExpr& member, const Context& ctx) {
    member.base->type = Type::error();  // `instance` is not a value of its own
    if (ctx.fold || ctx.fn || (ctx.where != Where::Object && ctx.where != Where::Spawn && ctx.where != Where::Trigger)) {
        const char* place = ctx.fold ? "the term of a fold: it reads this object's equations and `other.NAME`"
                            : ctx.where == Where::Fn || ctx.fn ? "a function: functions are pure; pass it as a parameter"
                                                               : "a constant expression";
        diags_.error(member.range, fmt::format("`instance` cannot be read in {}", place));
        return Type::error();
    }
    int found = findInstanceMember(member.member);
    if (found < 0) {
        std::vector<std::string> names;
        for (const InstanceMember& m : instanceMembers()) names.emplace_back(m.name);
        std::string suggestion = closestName(member.member, names);
        std::string all;
        for (const std::string& n : names) all += fmt::format("{}`{}`", all.empty() ? "" : ", ", n);
        Diagnostic& d = diags_.error(member.memberRange,
                                     fmt::format("`instance` has no member `{}`{}; it has {}", member.member,
                                                 suggestion.empty() ? "" : fmt::format(" (did you mean `{}`?)", suggestion),
                                                 all));
        if (!suggestion.empty()) d.fixes.push_back({fmt::format("Change to `{}`", suggestion), member.memberRange, suggestion});
        return Type::error();
    }
    member.instance = found;
    program_.instanced = true;
    return instanceMembers()[static_cast<size_t>(found)].width == 1 ? Type::scalar() : Type::vec(3);
}

Type Checker::checkMember(MemberExpr& member, const Context& ctx) {
    if (member.base->kind == ExprKind::Name && static_cast<NameExpr&>(*member.base).name == "other") {
        if (ctx.fold) return checkNeighbourMember(member, ctx);
        bool declared = globals_.count("other") || (ctx.object && objectScopes_[ctx.object].names.count("other")) || ctx.fn ||
                        ctx.trigger;
        if (!declared) {
            diags_.error(member.base->range, "`other` is the neighbour in the term of a fold (`near_sum(type, radius, "
                                             "term)`); there is none here");
            return Type::error();
        }
    }
    if (member.base->kind == ExprKind::Name && static_cast<NameExpr&>(*member.base).name == kInstanceName)
        return checkInstanceMember(member, ctx);
    // `rocket.pos`: a live read of an enclosing object.
    if (member.base->kind == ExprKind::Name) {
        auto& base = static_cast<NameExpr&>(*member.base);
        int depth = 0;
        if (const ObjectDecl* parent = enclosingObject(base.name, ctx, &depth)) {
            if (ctx.fold) {
                diags_.error(member.range, fmt::format("the term of `{}` cannot read `{}`: it may read this object's "
                                                       "equations, `other.NAME`, constants and externs",
                                                       ctx.fold->callee, base.name));
                return Type::error();
            }
            member.parent = parent;
            member.parentDepth = depth;
            base.type = Type::error();  // an object is not a value of its own
            Ref& ref = member.parentRef;
            if (member.member == "alive") ref.kind = Ref::Kind::Alive;
            else if (member.member == "age") ref.kind = Ref::Kind::Age;
            else if (auto found = memberOf(*parent, member, {"alive", "age"})) ref = *found;
            else return Type::error();
            return typeOfRef(ref);
        }
        bool isObject = false;
        if (auto it = globals_.find(base.name); it != globals_.end()) isObject = it->second->kind == DeclKind::Object;
        isObject |= nestedObjects_.count(base.name) > 0;
        // A name of the object's own, or a function's or trigger's parameter or `let`, is a
        // value, whatever object has that name (`p.yxz` in a library function whose `p` is
        // a parameter, imported by a program with an object `p`).
        bool local = false;
        if (ctx.fn) {
            for (size_t i = 0; i < ctx.letsVisible; ++i) local |= ctx.fn->lets[i]->name == base.name;
            for (const auto& p : ctx.fn->params) local |= p.name == base.name;
        }
        if (ctx.trigger)
            for (const auto& p : ctx.trigger->params) local |= p.name == base.name;
        bool shadowed = local || (ctx.where == Where::Object && ctx.object && objectScopes_[ctx.object].names.count(base.name));
        if (isObject && !shadowed) {
            diags_.error(base.range, ctx.where == Where::Object
                                         ? fmt::format("`{}` is not an enclosing object of `{}`; an object can read "
                                                       "only the objects it is declared in", base.name, ctx.object->name)
                                         : fmt::format("`{}` is an object; only the objects declared inside it can "
                                                       "read it", base.name));
            return Type::error();
        }
    }
    // A swizzle: `.xyz`, `.rgb`, … on a vector.
    Type base = check(*member.base, ctx);
    if (base.isVague()) return base;
    if (!base.isVector()) {
        diags_.error(member.memberRange, fmt::format("{} has no components; `.{}` needs a vector", base.str(), member.member));
        return Type::error();
    }
    static const std::string sets[] = {"xyzw", "rgba"};
    const std::string* chosen = nullptr;
    for (auto& set : sets)
        if (set.find(member.member[0]) != std::string::npos) chosen = &set;
    if (member.member.size() > 4 || !chosen) {
        diags_.error(member.memberRange, fmt::format("`.{}` is not a swizzle: use up to four of x, y, z, w or of r, g, b, a",
                                                     member.member));
        return Type::error();
    }
    member.swizzle.clear();
    for (char ch : member.member) {
        size_t index = chosen->find(ch);
        if (index == std::string::npos) {
            diags_.error(member.memberRange, fmt::format("`.{}` mixes the component sets xyzw and rgba", member.member));
            return Type::error();
        }
        if (static_cast<int>(index) >= base.width()) {
            diags_.error(member.memberRange, fmt::format("`.{}` reads component `{}`, but {} has only {} components",
                                                         member.member, ch, base.str(), base.width()));
            return Type::error();
        }
        member.swizzle.push_back(static_cast<int>(index));
    }
    return Type::vec(static_cast<int>(member.swizzle.size()));
}

Type Checker::checkCall(CallExpr& call, const Context& ctx) {
    if (core::neighbourFold(call.callee) && !globals_.count(call.callee)) return checkNear(call, ctx);
    std::vector<Type> args;
    for (auto& a : call.args) args.push_back(check(*a, ctx));

    if (auto it = globals_.find(call.callee); it != globals_.end()) {
        Decl* decl = it->second;
        if (decl->kind == DeclKind::Fn) {
            call.fn = static_cast<const FnDecl*>(decl);
            checkFn(*call.fn);
            if (ctx.fold) checkFoldCall(call, ctx);
            return checkUserCall(call, *call.fn, args);
        }
        const char* hint = decl->kind == DeclKind::Object ? "; create one with `emit`" : "";
        diags_.error(call.calleeRange, fmt::format("`{}` is not a function{}", call.callee, hint))
            .notes.push_back({decl->nameRange, "declared here"});
        return Type::error();
    }
    call.builtin = findBuiltinFunction(call.callee);
    if (call.builtin < 0) {
        reportUnknown("function", call.callee, call.calleeRange, [&] {
            std::vector<std::string> candidates;
            for (auto& f : builtinFunctions()) candidates.emplace_back(f.name);
            for (std::string& n : globalNames({DeclKind::Fn})) candidates.push_back(std::move(n));
            return candidates;
        });
        return Type::error();
    }
    return checkBuiltinCall(call, args, ctx);
}

Type Checker::checkUserCall(CallExpr& call, const FnDecl& fn, const std::vector<Type>& args) {
    if (args.size() != fn.params.size()) {
        diags_.error(call.range, fmt::format("`{}` takes {} argument{}, but {} {} given", fn.name, fn.params.size(),
                                             fn.params.size() == 1 ? "" : "s", args.size(), args.size() == 1 ? "was" : "were"))
            .notes.push_back({fn.nameRange, fmt::format("`{}` declared here", fn.name)});
        return fn.resultType.isVague() ? Type::error() : fn.resultType;
    }
    for (size_t i = 0; i < args.size(); ++i) {
        const Param& p = fn.params[i];
        if (!args[i].isVague() && !p.type.type.isVague() && args[i] != p.type.type)
            diags_.error(call.args[i]->range, fmt::format("argument {} of `{}` (`{}`) must be {}, found {}", i + 1, fn.name,
                                                          p.name, p.type.type.str(), args[i].str()))
                .notes.push_back({p.nameRange, "parameter declared here"});
    }
    return fn.resultType;
}

Type Checker::checkBuiltinCall(CallExpr& call, const std::vector<Type>& args, const Context& ctx) {
    const BuiltinFunction& fn = builtinFunction(call.builtin);
    int n = static_cast<int>(args.size());
    if (n < fn.minArgs || n > fn.maxArgs) {
        std::string expected = fn.minArgs == fn.maxArgs ? std::to_string(fn.minArgs)
                                                        : fmt::format("{} to {}", fn.minArgs, fn.maxArgs);
        diags_.error(call.range, fmt::format("`{}` takes {} argument{}, but {} {} given", fn.name, expected,
                                             fn.maxArgs == 1 ? "" : "s", n, n == 1 ? "was" : "were"))
            .notes.push_back({call.calleeRange, fmt::format("{}", fn.signature)});
        return Type::error();
    }
    // Where temporal and random functions may appear.
    if (isTemporal(fn.rule) && ctx.where != Where::Object) {
        diags_.error(call.calleeRange, fmt::format("`{}` cannot be used in {}: only object equations have a history",
                                                   fn.name, placeWords(ctx.where)));
        return Type::error();
    }
    if (ctx.fold && (isTemporal(fn.rule) || fn.rule == BuiltinRule::Random)) {
        diags_.error(call.calleeRange, fmt::format("`{}` cannot be used in the term of `{}`: a term is a function of "
                                                   "the two objects as they are", fn.name, ctx.fold->callee));
        return Type::error();
    }
    if (fn.rule == BuiltinRule::Random &&
        (ctx.where == Where::Const || ctx.where == Where::ExternValue || ctx.where == Where::Attribute)) {
        diags_.error(call.calleeRange, fmt::format("`{}` cannot be used in {}: it must be the same in every run",
                                                   fn.name, placeWords(ctx.where)));
        return Type::error();
    }
    for (const Type& a : args)
        if (a.isError()) return Type::error();
    auto argError = [&](size_t i, std::string message) {
        diags_.error(call.args[i]->range, std::move(message)).notes.push_back({call.calleeRange, std::string(fn.signature)});
        return Type::error();
    };
    auto requireNumeric = [&]() -> bool {
        for (size_t i = 0; i < args.size(); ++i)
            if (!args[i].isVague() && !args[i].isNumeric()) {
                argError(i, fmt::format("argument {} of `{}` must be a number or vector, found {}", i + 1, fn.name,
                                        args[i].str()));
                return false;
            }
        return true;
    };
    // An argument not known yet (an equation that reads itself): the result's type where it
    // does not depend on it — a constructor's width is its name's (`x = integrate(vec4(…,
    // -x.w))` is a vec4), a length a float; the arguments are checked once they are known.
    for (const Type& a : args)
        if (a.isUnknown() && fn.rule != BuiltinRule::Componentwise && fn.rule != BuiltinRule::Integrate &&
            fn.rule != BuiltinRule::Snapshot && fn.rule != BuiltinRule::Prev)
            return fn.rule == BuiltinRule::ToScalar    ? Type::scalar()
                   : fn.rule == BuiltinRule::Construct ? Type::vec(fn.width)
                                                       : Type::unknown();

    switch (fn.rule) {
        case BuiltinRule::Componentwise: {
            if (!requireNumeric()) return Type::error();
            Type t = args.front();
            for (size_t i = 1; i < args.size(); ++i) {
                Type next = broadcast(t, args[i]);
                if (next.isError())
                    return argError(i, fmt::format("arguments of `{}` have different sizes: {} and {}", fn.name,
                                                   t.str(), args[i].str()));
                t = next;
            }
            return t;
        }
        case BuiltinRule::ToScalar:
            if (!requireNumeric()) return Type::error();
            if (args.size() == 2 && args[0] != args[1])
                return argError(1, fmt::format("arguments of `{}` must have the same type, found {} and {}", fn.name,
                                               args[0].str(), args[1].str()));
            return Type::scalar();
        case BuiltinRule::SameVector:
            if (!requireNumeric()) return Type::error();
            if (!args[0].isVector()) return argError(0, fmt::format("`{}` needs a vector, found {}", fn.name, args[0].str()));
            if (args.size() == 2 && args[0] != args[1])
                return argError(1, fmt::format("arguments of `{}` must have the same type, found {} and {}", fn.name,
                                               args[0].str(), args[1].str()));
            return args[0];
        case BuiltinRule::Cross:
            for (size_t i = 0; i < 2; ++i)
                if (args[i] != Type::vec(3))
                    return argError(i, fmt::format("`cross` needs vec3 arguments, found {}", args[i].str()));
            return Type::vec(3);
        case BuiltinRule::Rotate:
            if (args[0] != Type::vec(3))
                return argError(0, fmt::format("`{}` rotates a vec3, found {}", fn.name, args[0].str()));
            if (!args[1].isFloat())
                return argError(1, fmt::format("the angle of `{}` must be a float (radians), found {}", fn.name, args[1].str()));
            return Type::vec(3);
        case BuiltinRule::Construct: {
            if (!requireNumeric()) return Type::error();
            if (args.size() == 1 && args[0].isFloat()) return Type::vec(fn.width);
            int total = 0;
            std::string parts;
            for (const Type& a : args) {
                total += a.width();
                parts += (parts.empty() ? "" : " + ") + a.str();
            }
            if (total != fn.width) {
                diags_.error(call.range, fmt::format("`{}` needs {} components, but got {} ({})", fn.name, fn.width,
                                                     total, parts))
                    .notes.push_back({call.calleeRange, std::string(fn.signature)});
                return Type::error();
            }
            return Type::vec(fn.width);
        }
        case BuiltinRule::Integrate:
            if (!requireNumeric()) return Type::error();
            return args[0];
        case BuiltinRule::Snapshot:
        case BuiltinRule::Prev:
            return args[0];
        case BuiltinRule::Random:
            return Type::vec(fn.width);
        case BuiltinRule::Neighbours: break;  // (checkNear)
    }
    return Type::error();
}

}  // namespace psys::detail
