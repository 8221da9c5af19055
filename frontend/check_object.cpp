// Checking objects: their names, equations, commands and nested objects. Their equations'
// types are inferred first, every object's together (check_infer.cpp); each object is
// then checked once with diagnostics on.
#include <cctype>
#include <cmath>
#include <filesystem>
#include <span>

#include <fmt/format.h>

#include "core/integrators.h"
#include "frontend/builtins.h"
#include "frontend/checker.h"
#include "frontend/consteval.h"

namespace psys::detail {

using namespace ast;

namespace {

// "@integrator(method), @step(seconds) and @capacity(count)"
std::string attributeList() {
    std::string list;
    auto all = builtinAttributes();
    for (size_t i = 0; i < all.size(); ++i)
        list += (i == 0 ? "" : i + 1 == all.size() ? " and " : ", ") + std::string(all[i].signature);
    return list;
}

}  // namespace

// Into a fresh scope: inferObjects declares every object's names (diagnostics held back),
// checkObject again with them on; both give the same scope.
void Checker::declareObjectNames(ObjectDecl& object) {
    ObjectScope scope;
    auto declare = [&](const std::string& name, SourceRange range, Ref ref, const char* what) {
        if (!checkDeclarableName(name, range, what)) return;
        if (auto it = scope.declaredAt.find(name); it != scope.declaredAt.end()) {
            bool bothParams = ref.kind == Ref::Kind::Param && scope.names[name].kind == Ref::Kind::Param;
            if (bothParams) return;  // checkParams has said so
            diags_.error(range, fmt::format("`{}` is defined twice in object `{}`", name, object.name))
                .notes.push_back({it->second, "first defined here"});
            return;
        }
        if (auto g = globals_.find(name); g != globals_.end() &&
                                          (g->second->kind == DeclKind::Const || g->second->kind == DeclKind::Extern))
            diags_.warning(range, fmt::format("{} `{}` hides the file-level {} of the same name",
                                              std::string_view(what).substr(std::string_view(what).find(' ') + 1), name,
                                              g->second->kind == DeclKind::Const ? "constant" : "extern"))
                .notes.push_back({g->second->nameRange, "hidden declaration"});
        scope.names[name] = ref;
        scope.declaredAt[name] = range;
    };
    checkParams(object.params, "an object");
    for (size_t i = 0; i < object.params.size(); ++i) {
        Ref ref;
        ref.kind = Ref::Kind::Param;
        ref.object = &object;
        ref.index = static_cast<int>(i);
        declare(object.params[i].name, object.params[i].nameRange, ref, "a parameter");
    }
    for (auto& eq : object.equations) {
        for (size_t i = 0; i < eq->names.size(); ++i) {
            Ref ref;
            ref.kind = Ref::Kind::Equation;
            ref.object = &object;
            ref.equation = eq.get();
            ref.index = static_cast<int>(i);
            declare(eq->names[i], eq->nameRanges[i], ref, "an equation");
        }
    }
    objectScopes_[&object] = std::move(scope);
}

// Checks one equation's value and records the types of the names it defines. On the final
// pass, also reports shape mismatches.
void Checker::checkEquation(Equation& eq, const Context& ctx, bool final) {
    Type t = check(*eq.value, ctx);
    // While inferring, a failed check keeps the last good guess: the final pass then
    // reports the real mismatch instead of a silent cascade from an error type.
    if (!final && t.isError()) return;
    if (!eq.isTuple()) {
        if (t.isTuple()) {
            if (final)
                diags_.error(eq.value->range, fmt::format("the value is a tuple {}, but `{}` names one value; write "
                                                          "`({}) = …` to take it apart", t.str(), eq.names[0],
                                                          [&] {
                                                              std::string s;
                                                              for (size_t i = 0; i < t.elements().size(); ++i)
                                                                  s += (i ? ", " : "") + fmt::format("{}{}", eq.names[0], i + 1);
                                                              return s;
                                                          }()));
            t = Type::error();
        }
        if (eq.annotation) {
            if (final && !t.isVague() && t != eq.annotation->type)
                diags_.error(eq.value->range, fmt::format("`{}` is declared {} but its value is {}", eq.names[0],
                                                          eq.annotation->type.str(), t.str()))
                    .notes.push_back({eq.annotation->range, "declared type"});
            return;  // an annotation is authoritative
        }
        eq.types[0] = t;
        return;
    }
    if (t.isVague()) {
        if (t.isError())
            for (auto& et : eq.types) et = Type::error();
        return;
    }
    if (!t.isTuple() || t.elements().size() != eq.names.size()) {
        if (final)
            diags_.error(eq.value->range, fmt::format("{} names are defined here, but the value is {}", eq.names.size(),
                                                      t.str()))
                .notes.push_back({eq.range, "a composite equation needs a tuple with one value per name"});
        for (auto& et : eq.types) et = Type::error();
        return;
    }
    eq.types = t.elements();
}

void Checker::checkArguments(std::vector<ExprPtr>& args, const ObjectDecl& target, SourceRange callRange,
                             const Context& ctx) {
    std::vector<Type> types;
    for (auto& a : args) types.push_back(check(*a, ctx));
    if (args.size() != target.params.size()) {
        std::string params;
        for (auto& p : target.params) params += (params.empty() ? "" : ", ") + p.name + ": " + p.type.type.str();
        diags_.error(callRange, fmt::format("`{}` takes {} argument{} ({}), but {} {} given", target.name,
                                            target.params.size(), target.params.size() == 1 ? "" : "s", params,
                                            args.size(), args.size() == 1 ? "was" : "were"))
            .notes.push_back({target.nameRange, fmt::format("`{}` declared here", target.name)});
        return;
    }
    for (size_t i = 0; i < args.size(); ++i) {
        const Param& p = target.params[i];
        if (!types[i].isVague() && !p.type.type.isVague() && types[i] != p.type.type)
            diags_.error(args[i]->range, fmt::format("argument {} of `{}` (`{}`) must be {}, found {}", i + 1,
                                                     target.name, p.name, p.type.type.str(), types[i].str()))
                .notes.push_back({p.nameRange, "parameter declared here"});
    }
}

void Checker::checkEmit(Command& emit, const Context& ctx) {
    emit.targetDecl = findEmitTarget(emit.target, emit.targetRange, ctx);
    SourceRange callRange = emit.args.empty() ? emit.targetRange
                                              : SourceRange::join(emit.targetRange, emit.args.back()->range);
    if (emit.targetDecl) {
        createdObjects_.insert(emit.targetDecl);
        checkArguments(emit.args, *emit.targetDecl, callRange, ctx);
    } else {
        for (auto& a : emit.args) check(*a, ctx);
    }
    // A constant rate or count must be a number of objects: not negative, not NaN, not infinite.
    auto checkAmount = [&](Expr& e, const char* what, const char* type) {
        check(e, ctx);
        if (!expectType(e, Type::scalar(), type)) return;
        auto v = evaluateConstant(e);
        if (!v) return;
        if (!std::isfinite(v->v[0])) diags_.error(e.range, fmt::format("the emission {} is not a finite number ({})", what, numberText(v->v[0])));
        else if (v->v[0] < 0) diags_.error(e.range, fmt::format("the emission {} is negative ({})", what, v->v[0]));
    };
    if (emit.rate) {
        if (ctx.where == Where::Trigger)
            diags_.error(emit.rate->range, "a trigger runs once when fired: it cannot emit at a rate; use `count N`");
        else if (ctx.dying)
            diags_.error(emit.rate->range, "an object dies once: `on death` cannot emit at a rate; use `count N`");
        else
            checkAmount(*emit.rate, "rate", "an emission rate (per second)");
    }
    if (emit.count) checkAmount(*emit.count, "count", "an emission count");
    // What makes it never fire, where the program says so in constants.
    for (Expr* amount : {emit.rate.get(), emit.count.get()}) {
        if (!amount || amount->type.isError()) continue;
        if (auto v = evaluateConstant(*amount); v && v->v[0] >= 0 && v->v[0] < 1)
            diags_.warning(amount->range, fmt::format("this `emit` never creates anything: its {} is {}",
                                                      amount == emit.rate.get() ? "rate" : "count", numberText(v->v[0])));
    }
}

namespace {
bool anyKill(const std::vector<CommandPtr>& commands) {
    for (auto& c : commands)
        if (c->kind == CommandKind::Kill || anyKill(c->body)) return true;
    return false;
}
}  // namespace

// `on death { … }`: bursts in the update that kills the object (docs/language.md).
void Checker::checkOn(Command& on, const Context& ctx, const Command** point) {
    if (ctx.where != Where::Object) {
        diags_.error(on.keywordRange, "`on death` belongs in an object; a trigger has no death");
        return;
    }
    if (ctx.block) {
        diags_.error(on.keywordRange, fmt::format("`on {}` must be in the object's body, not inside `{}`", on.event,
                                                  ctx.block->kind == CommandKind::On ? "on" : "when"))
            .notes.push_back({ctx.block->keywordRange, "inside this"});
        return;
    }
    if (on.event != "death") {
        diags_.error(on.eventRange, fmt::format("unknown event `{}`: `on` takes `death`", on.event));
        return;
    }
    if (!anyKill(ctx.object->commands))
        diags_.warning(on.keywordRange, fmt::format("object `{}` never dies (it has no `kill`): `on death` never runs",
                                                    ctx.object->name));
    Context inner = ctx;
    inner.block = &on;
    inner.dying = true;
    checkCommands(on.body, inner, point);
}

// `point`, `sprite`, `streak`: how the object is drawn, at most one per object.
void Checker::checkDraw(Command& cmd, const Context& ctx, const Command** point) {
    std::string_view name = core::drawKindName(cmd.draw);
    if (ctx.where != Where::Object) {
        diags_.error(cmd.keywordRange, fmt::format("`{}` draws an object; a trigger can only emit objects", name));
        return;
    }
    if (ctx.dying) {
        diags_.error(cmd.keywordRange, "`on death` can only emit: the object is gone, it draws nothing");
        return;
    }
    if (*point) {
        std::string_view first = core::drawKindName((*point)->draw);
        diags_.error(cmd.keywordRange, fmt::format("object `{}` already draws a {}; an object draws at most one",
                                                   ctx.object->name, first))
            .notes.push_back({(*point)->keywordRange, fmt::format("the first `{}` is here", first)});
    } else {
        *point = &cmd;
    }
    std::vector<Type> types;
    for (auto& a : cmd.args) types.push_back(check(*a, ctx));
    const core::DrawSignature p = core::drawSignature(cmd.draw);
    if (cmd.args.size() < p.required || cmd.args.size() > p.count) {
        std::string list;
        for (size_t i = 0; i < p.count; ++i)
            list += fmt::format("{}{}: {}", i == 0 ? "" : i >= p.required ? "[, " : ", ", p.params[i].name,
                                drawParamType(p.params[i]).str());
        for (size_t i = p.required; i < p.count; ++i) list += "]";
        std::string count = p.required == p.count ? fmt::format("{}", p.required)
                                                  : fmt::format("{} to {}", p.required, p.count);
        diags_.error(cmd.range, fmt::format("`{}` takes {} arguments ({}), but {} {} given", name, count,
                                            list, cmd.args.size(), cmd.args.size() == 1 ? "was" : "were"));
        return;
    }
    for (size_t i = 0; i < cmd.args.size(); ++i) {
        const core::DrawParam& param = p.params[i];
        Type type = drawParamType(param);
        if (type == Type::vec(4) && types[i] == Type::vec(3))
            diags_.error(cmd.args[i]->range, fmt::format("the colour of a {} must be vec4 (color), found vec3", name))
                .notes.push_back({cmd.args[i]->range, "add an alpha: `vec4(c, 1)`"});
        else if (expectType(*cmd.args[i], type, fmt::format("the {} of a {}", param.name, name)) &&
                 param.role == core::DrawRole::Length)
            checkTrailLength(cmd, *cmd.args[i]);
    }
}

// A trail's length is how many points of history the object keeps (state the compiler
// adds): a number the program fixes, not a value that changes.
void Checker::checkTrailLength(Command& cmd, const Expr& length) {
    auto v = evaluateConstant(length);
    if (!v || !(v->v[0] >= 2 && v->v[0] <= core::kMaxTrail) || v->v[0] != std::floor(v->v[0])) {
        std::string found = !v ? "it is not a constant" : fmt::format("it is {}", numberText(v->v[0]));
        diags_.error(length.range, fmt::format("a trail's length must be a constant whole number from 2 to {} (the "
                                               "points it keeps); {}", core::kMaxTrail, found));
        return;
    }
    cmd.trailPoints = static_cast<int>(v->v[0]);
}

void Checker::checkCommands(std::vector<CommandPtr>& commands, const Context& ctx, const Command** point) {
    for (auto& cmd : commands) {
        switch (cmd->kind) {
            case CommandKind::Draw: checkDraw(*cmd, ctx, point); break;
            case CommandKind::Kill:
                if (ctx.where != Where::Object) {
                    diags_.error(cmd->keywordRange, "`kill` removes an object; a trigger can only emit objects");
                    break;
                }
                if (ctx.dying) {
                    diags_.error(cmd->keywordRange, "`on death` can only emit: the object is already dying");
                    break;
                }
                if (cmd->cond) {
                    check(*cmd->cond, ctx);
                    expectType(*cmd->cond, Type::boolean(), "the condition of `kill when`");
                }
                break;
            case CommandKind::Emit: checkEmit(*cmd, ctx); break;
            case CommandKind::When: {
                check(*cmd->cond, ctx);
                if (expectType(*cmd->cond, Type::boolean(), "the condition of `when`"))
                    if (auto v = evaluateConstant(*cmd->cond); v && !v->isTrue())
                        diags_.warning(cmd->cond->range, "this condition is always false: nothing in this `when` ever happens");
                Context inner = ctx;
                inner.block = cmd.get();
                checkCommands(cmd->body, inner, point);
                break;
            }
            case CommandKind::On: checkOn(*cmd, ctx, point); break;
            case CommandKind::Notify: checkNotify(*cmd, ctx); break;
        }
    }
}

// `notify "hit"(pos, speed)`: an event the host reads after the step, with its values
// (docs/language.md, "Events"). Every `notify` of a name gives the same types.
void Checker::checkNotify(Command& cmd, const Context& ctx) {
    if (ctx.where != Where::Object && ctx.where != Where::Trigger) {
        diags_.error(cmd.keywordRange, "`notify` belongs in an object or a trigger");
        return;
    }
    bool named = !cmd.event.empty() && cmd.event.size() <= 64 && !std::isdigit(static_cast<unsigned char>(cmd.event[0]));
    for (char c : cmd.event) named &= std::isalnum(static_cast<unsigned char>(c)) || c == '_';
    if (!named) {
        diags_.error(cmd.eventRange, fmt::format("an event's name is letters, digits and `_` (up to 64, not starting "
                                                 "with a digit), as a host spells it: not \"{}\"", cmd.event));
        return;
    }
    std::vector<Type> types;
    bool ok = true;
    for (auto& a : cmd.args) {
        Type t = check(*a, ctx);
        if (t.isVague()) {
            ok = false;
        } else if (!t.isNumeric()) {
            diags_.error(a->range, fmt::format("an event's values are numbers (float or vecN), not {}", t.str()));
            ok = false;
        }
        types.push_back(t);
    }
    if (!ok) return;
    for (ast::Program::Event& e : program_.events) {
        if (e.name != cmd.event) continue;
        if (e.types != types) {
            auto list = [](const std::vector<Type>& ts) {
                std::string out;
                for (const Type& t : ts) out += (out.empty() ? "" : ", ") + t.str();
                return "(" + out + ")";
            };
            diags_.error(cmd.range, fmt::format("event \"{}\" gives {} here and {} where it is first notified: a "
                                                "host reads one layout an event",
                                                cmd.event, list(types), list(e.types)))
                .notes.push_back({e.range, "first notified here"});
        }
        return;
    }
    program_.events.push_back({cmd.event, types, cmd.range});
}

void Checker::checkAttributes(const std::vector<Attribute*>& attributes) {
    std::map<std::string, SourceRange> seen;
    Context ctx;
    ctx.where = Where::Attribute;
    for (Attribute* attribute : attributes) {
        Attribute& a = *attribute;
        if (auto it = seen.find(a.name); it != seen.end()) {
            diags_.error(a.range, fmt::format("`@{}` is given twice", a.name)).notes.push_back({it->second, "first given here"});
            continue;
        }
        seen[a.name] = a.range;
        if (a.text && a.name != "texture") {
            diags_.error(a.textRange, fmt::format("`@{}` takes no file name", a.name));
            continue;
        }
        auto wantOneArg = [&](const char* what) {
            if (a.args.size() == 1) return true;
            diags_.error(a.range, fmt::format("`@{}` takes one argument: {}", a.name, what));
            return false;
        };
        if (a.name == "integrator") {
            std::string names;
            auto all = integratorNames();
            for (size_t i = 0; i < all.size(); ++i)
                names += (i == 0 ? "" : i + 1 == all.size() ? " and " : ", ") + std::string(all[i]);
            if (!wantOneArg("the integration method")) continue;
            auto* name = a.args[0]->kind == ExprKind::Name ? static_cast<NameExpr*>(a.args[0].get()) : nullptr;
            bool known = false;
            for (auto n : integratorNames()) known |= name && name->name == n;
            if (known) continue;
            // Velocity Verlet goes by several names; the language calls it leapfrog.
            bool verlet = name && (name->name.find("verlet") != std::string::npos ||
                                   name->name.find("Verlet") != std::string::npos);
            Diagnostic& d = diags_.error(
                a.args[0]->range, !name ? std::string("the integrator must be named")
                                  : verlet ? fmt::format("unknown integrator `{}`; velocity Verlet is `leapfrog`", name->name)
                                           : fmt::format("unknown integrator `{}`", name->name));
            d.notes.push_back({a.args[0]->range, "the integrators are " + names});
            if (verlet) d.fixes.push_back({"Change to `leapfrog`", a.args[0]->range, "leapfrog"});
        } else if (a.name == "step") {
            if (!wantOneArg("the fixed sub-step in seconds, such as 1/240")) continue;
            check(*a.args[0], ctx);
            if (!expectType(*a.args[0], Type::scalar(), "the step")) continue;
            auto v = evaluateConstant(*a.args[0]);
            if (!a.args[0]->type.isError() && v && !std::isfinite(v->v[0]))  // (1/0 was taken as no step at all)
                diags_.error(a.args[0]->range, fmt::format("the step is not a finite number ({})", numberText(v->v[0])));
            else if (!a.args[0]->type.isError() && (!v || !(v->v[0] > 0)))
                diags_.error(a.args[0]->range, "the step must be a positive constant number of seconds");
            a.value = v;
        } else if (a.name == "tolerance") {
            checkTolerance(a, ctx);
        } else if (a.name == "precision") {
            if (!wantOneArg("float or double")) continue;
            auto* name = a.args[0]->kind == ExprKind::Name ? static_cast<NameExpr*>(a.args[0].get()) : nullptr;
            if (name && core::precisionFromName(name->name)) continue;
            diags_.error(a.args[0]->range, name ? fmt::format("unknown precision `{}`", name->name)
                                                : std::string("the precision must be named"))
                .notes.push_back({a.args[0]->range, "the precisions are float (the default) and double"});
        } else if (a.name == "capacity") {
            if (!wantOneArg("the most objects of this type alive at once")) continue;
            check(*a.args[0], ctx);
            if (!expectType(*a.args[0], Type::scalar(), "the capacity")) continue;
            auto v = evaluateConstant(*a.args[0]);
            std::optional<double> n;
            if (a.args[0]->kind == ExprKind::Number) n = static_cast<const NumberExpr&>(*a.args[0]).value;
            else if (v) n = v->v[0];
            // Rows are numbered with 32 bits.
            if (!a.args[0]->type.isError() && (!n || !(*n >= 1 && *n <= 4294967295.0) || *n != std::floor(*n)))
                diags_.error(a.args[0]->range, "the capacity must be a constant whole number from 1 to 4294967295");
            a.value = v;
            a.whole = n;
        } else if (a.name == "texture") {
            checkTexture(a, ctx);
        } else if (a.name == "shape" || a.name == "blend") {
            bool shape = a.name == "shape";
            std::string names;
            auto all = shape ? std::span<const std::string_view>(core::kShapeNames) : std::span<const std::string_view>(core::kBlendNames);
            for (size_t i = 0; i < all.size(); ++i)
                names += (i == 0 ? "" : i + 1 == all.size() ? " and " : ", ") + std::string(all[i]);
            if (!wantOneArg(shape ? "the sprite's shape" : "add or alpha")) continue;
            auto* name = a.args[0]->kind == ExprKind::Name ? static_cast<NameExpr*>(a.args[0].get()) : nullptr;
            bool known = name && (shape ? core::shapeFromName(name->name).has_value() : core::blendFromName(name->name).has_value());
            if (!known)
                diags_.error(a.args[0]->range, name ? fmt::format("unknown {} `{}`", shape ? "shape" : "blend", name->name)
                                                    : fmt::format("the {} must be named", shape ? "shape" : "blend"))
                    .notes.push_back({a.args[0]->range, fmt::format("the {} are {}", shape ? "shapes" : "blends", names)});
        } else {
            diags_.error(a.nameRange, fmt::format("unknown attribute `@{}`", a.name))
                .notes.push_back({a.nameRange, "the attributes are " + attributeList()});
        }
    }
}

// `@texture("file.png"[, columns, rows])`: a file next to the program (a warning where
// there is none: the system runs, the viewer draws the shape), and a flip-book's grid of
// frames (constant whole numbers).
void Checker::checkTexture(Attribute& a, const Context& ctx) {
    if (!a.text) {
        diags_.error(a.range, "`@texture` takes a file name first: @texture(\"file.png\"[, columns, rows])");
        return;
    }
    if (a.args.size() != 0 && a.args.size() != 2) {
        diags_.error(a.range, "`@texture` takes a file name, then the flip-book's columns and rows (both or neither)");
        return;
    }
    ConstValue grid{Type::vec(2), {1, 1, 0, 0}};  // columns, rows: for the lowering
    for (size_t i = 0; i < a.args.size(); ++i) {
        Expr& arg = *a.args[i];
        check(arg, ctx);
        if (!expectType(arg, Type::scalar(), "a flip-book's columns and rows")) continue;
        auto v = evaluateConstant(arg);
        if (!v || !(v->v[0] >= 1 && v->v[0] <= 64) || v->v[0] != std::floor(v->v[0]))
            diags_.error(arg.range, "a flip-book's columns and rows must be constant whole numbers from 1 to 64");
        else
            grid.v[i] = v->v[0];
    }
    a.value = grid;
    std::filesystem::path file = besideSource(diags_.sources(), a.textRange, *a.text);
    std::error_code error;
    if (!std::filesystem::is_regular_file(file, error))
        diags_.warning(a.textRange, fmt::format("there is no texture file `{}` (looked for {}): the sprites are drawn "
                                                "with their shape", *a.text, file.string()));
}

// `@tolerance(metres[, seconds])`: positive constant numbers; the compiler meets them by
// choosing the integrator and sub-step (tune/tolerance.h).
void Checker::checkTolerance(Attribute& a, const Context& ctx) {
    if (a.args.empty() || a.args.size() > 2) {
        diags_.error(a.range, "`@tolerance` takes the largest position error in metres, then, if wanted, the seconds "
                              "over which it holds: @tolerance(1e-3) or @tolerance(1e-3, 60)");
        return;
    }
    ConstValue value{Type::vec(2), {0, 0, 0, 0}};  // metres, seconds (0: the default time)
    for (size_t i = 0; i < a.args.size(); ++i) {
        Expr& arg = *a.args[i];
        int errors = diags_.errorCount();
        check(arg, ctx);
        const char* what = i == 0 ? "the tolerance" : "the time a tolerance holds over";
        if (!expectType(arg, Type::scalar(), what)) return;
        auto v = evaluateConstant(arg);
        if (diags_.errorCount() > errors) return;  // said already (an extern, say)
        if (!v || !std::isfinite(v->v[0]) || !(v->v[0] > 0)) {
            diags_.error(arg.range, i == 0 ? "the tolerance must be a positive constant number of metres"
                                           : "the time must be a positive constant number of seconds");
            return;
        }
        value.v[i] = v->v[0];
    }
    a.value = value;
}

void Checker::checkObject(ObjectDecl& object) {
    std::vector<Attribute*> attributes;
    for (auto& a : object.attributes) attributes.push_back(&a);
    checkAttributes(attributes);
    declareObjectNames(object);
    Context ctx;
    ctx.where = Where::Object;
    ctx.object = &object;
    for (auto& eq : object.equations) checkEquation(*eq, ctx, true);
    checkAlgebraicLoops(object);
    const Command* point = nullptr;
    checkCommands(object.commands, ctx, &point);
    const Attribute* shape = nullptr;
    for (const Attribute& a : object.attributes) {
        if (a.name == "texture" && shape) {
            diags_.error(a.nameRange, "`@texture` takes the place of `@shape`: give one of them")
                .notes.push_back({shape->nameRange, "`@shape` is here"});
            continue;
        }
        if (a.name == "shape" || a.name == "texture") shape = &a;
        if ((a.name == "shape" || a.name == "texture") && !(point && point->draw == core::DrawKind::Sprite))
            diags_.error(a.nameRange, fmt::format("`@{}` is a sprite's: object `{}` {}", a.name, object.name,
                                                  point ? fmt::format("draws with `{}`", core::drawKindName(point->draw))
                                                        : std::string("draws nothing")))
                .notes.push_back({point ? point->keywordRange : object.nameRange,
                                  point ? "draw it with `sprite(position, colour, size)`" : "the object"});
    }
    // (every object's equation types are inferred before any is checked: inferObjects)
    for (auto& child : object.children) checkObject(*child);
}

}  // namespace psys::detail
