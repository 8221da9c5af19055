// Lowering: the checked AST to IR behaviour kernels.
//
// Each object becomes one behaviour kernel that still says what the program said: the
// temporal constructs (integrate, derive, snapshot, prev, `->`), random draws and parent
// reads are instructions of their own, and opt/ makes them explicit state, keys and
// exports. What lowering decides is the order of evaluation, which is the language's
// semantics for recursive equations (docs/language.md, "Evaluation order"):
//
//   Equations are evaluated so that everything an equation reads in the same update is
//   computed before it; where that leaves a choice, one whose every reference (delayed
//   ones too) is computed already, then source order — so a cycle is cut once. A reference that
//   must read an equation evaluated later in this order — one that closes a cycle, which
//   the front end allows only through `integrate`, `prev` or the `next` side of `->` — is
//   a `recur` instruction: opt/resolve_cycles makes it the value of the previous update.
//   The operand of `prev` is the exception: it is only needed for the slot's next value,
//   once the update has computed everything, so it is lowered last and reads this
//   update's values.
//
// Functions are inlined; every inlined `rand` gets its own call site. Broadcasts become
// explicit `splat`s and the library functions (mix, clamp, rotate_y, normalize, …) become
// arithmetic, so later passes see every operation.
#include "lower/lower.h"

#include <fmt/format.h>

#include <functional>
#include <map>

#include "core/instances.h"
#include "lower/object_lowering.h"

namespace psys::lower {
namespace {

using namespace ast;
using namespace ir;
using ir::Module;
using ir::Param;
using ir::Type;
using detail::irType;
using detail::Locator;
using detail::ObjectLowering;
using detail::Values;

// ---------------------------------------------------------------- commands

struct CommandLowering {
    CommandLowering(ObjectLowering& lowering, Kernel& k, std::vector<EmitSite>& emits, const ast::Program& program,
                    std::function<std::string(const ObjectDecl*)> qualified, bool object)
        : lowering(lowering), k(k), emits(emits), program(program), qualified(std::move(qualified)), object(object) {}

    ObjectLowering& lowering;
    Kernel& k;
    std::vector<EmitSite>& emits;
    const ast::Program& program;
    std::function<std::string(const ObjectDecl*)> qualified;
    bool object = false;  // an object's behaviour (a trigger's or the start's: bursts only)

    // The commands of an object's body, then its `on death` blocks, guarded by the kill
    // flag the body computed.
    void runObject(const std::vector<CommandPtr>& commands, ValueId& kill) {
        run(commands, {}, kill);
        for (const Command* on : deaths_) {
            LocScope at(k, lowering.locate(on->range));
            dying_ = true;
            run(on->body, {kill}, kill);
            dying_ = false;
        }
    }

    // The render yields, by the command's parameters (core::drawSignature).
    void drawCommand(const Command& cmd, const std::vector<ValueId>& conditions) {
        const core::DrawSignature signature = core::drawSignature(cmd.draw);
        std::optional<ValueId> position;
        for (size_t i = 0; i < cmd.args.size() && i < signature.count; ++i) {
            if (signature.params[i].role == core::DrawRole::Length) continue;  // (the checker's cmd.trailPoints)
            ValueId v = lowering.lowerOne(*cmd.args[i]);
            YieldKind kind = drawnYield(signature.params[i].role);
            if (kind == YieldKind::Position) position = v;
            k.yields.push_back({kind, 0, 0, v});
        }
        if (cmd.draw == core::DrawKind::Trail && position) trailHistory(*position, cmd.trailPoints);
        k.yields.push_back({YieldKind::Visible, 0, 0, lowering.guard(conditions)});
        draw = cmd.draw;
        trail = cmd.draw == core::DrawKind::Trail ? cmd.trailPoints : 0;
    }

    static YieldKind drawnYield(core::DrawRole role) {
        switch (role) {
            case core::DrawRole::Position: return YieldKind::Position;
            case core::DrawRole::Color: return YieldKind::Color;
            case core::DrawRole::Size: return YieldKind::Size;
            case core::DrawRole::Rotation: return YieldKind::Rotation;
            case core::DrawRole::Frame: return YieldKind::Frame;
            case core::DrawRole::End: return YieldKind::End;
            case core::DrawRole::Length: break;
        }
        return YieldKind::Visible;
    }

    // A trail's points behind its head: the position at each of the last `points - 1`
    // updates, as the program would write them — `p1 = pos -> prev(pos)`, `p2 = pos ->
    // prev(p1)`, … (a new object's trail starts collapsed at its head). They are state
    // like any other: every backend computes them, hot reload carries them.
    void trailHistory(ValueId head, int points) {
        ValueId behind = head;
        for (int p = 0; p + 1 < points; ++p) {
            ValueId prev = lowering.temporal(Op::Prev, Type::vec(3), {behind});
            behind = lowering.temporal(Op::FollowedBy, Type::vec(3), {head, prev});
            k.yields.push_back({YieldKind::Trail, p, 0, behind});
        }
    }

    // `emit` (or `notify`, a burst of one object of its event's type) at a new site.
    void emit(const Command& cmd, const std::string& target, const std::vector<ValueId>& conditions) {
        int site = static_cast<int>(emits.size());
        EmitSite::When when = cmd.rate              ? EmitSite::When::Rate
                              : dying_              ? EmitSite::When::Death
                              : object && !conditions.empty() ? EmitSite::When::Edge
                                                    : EmitSite::When::Creation;
        emits.push_back({target, when});
        ValueId on = lowering.guard(conditions);
        // A burst in a `when` fires where the condition becomes true: it was
        // false at the previous update (`prev` is false at creation). Each
        // burst's `prev` is a call site of its own, so its state slot has a
        // name of its own (`prev#SITE`): hot reload carries state by name.
        if (when == EmitSite::When::Edge) {
            ValueId before = lowering.temporal(Op::Prev, Type::boolean(), {on});
            on = k.op(Op::And, Type::boolean(), {on, k.op(Op::Not, Type::boolean(), {before})});
        }
        ValueId zero = k.scalar(0);
        ValueId count = cmd.count ? lowering.lowerOne(*cmd.count) : k.scalar(1);
        if (cmd.rate) {
            ValueId rate = lowering.lowerOne(*cmd.rate);
            k.yields.push_back({YieldKind::EmitRate, site, 0, k.op(Op::Select, Type::f32(), {on, rate, zero})});
            k.yields.push_back({YieldKind::EmitCount, site, 0, count});
        } else {
            k.yields.push_back({YieldKind::EmitCount, site, 0, k.op(Op::Select, Type::f32(), {on, count, zero})});
        }
        lowering.perChild_ = true;
        for (size_t i = 0; i < cmd.args.size(); ++i)
            k.yields.push_back({YieldKind::EmitArg, site, static_cast<int>(i), lowering.lowerOne(*cmd.args[i])});
        lowering.perChild_ = false;
        if (program.instanced) {  // a child belongs to its emitter's instance
            k.yields.push_back({YieldKind::EmitArg, site, static_cast<int>(cmd.args.size()), lowering.instance()});
            if (object) instanceEmission(site);
        }
    }

    void run(const std::vector<CommandPtr>& commands, std::vector<ValueId> conditions, ValueId& kill) {
        for (auto& cmd : commands) {
            LocScope at(k, lowering.locate(cmd->range));
            switch (cmd->kind) {
                case CommandKind::Draw: drawCommand(*cmd, conditions); break;
                case CommandKind::Kill: {
                    ValueId c = cmd->cond ? lowering.lowerOne(*cmd->cond) : k.boolean(true);
                    ValueId guarded = k.op(Op::And, Type::boolean(), {lowering.guard(conditions), c});
                    kill = k.op(Op::Or, Type::boolean(), {kill, guarded});
                    break;
                }
                case CommandKind::Emit: emit(*cmd, qualified(cmd->targetDecl), conditions); break;
                case CommandKind::Notify: emit(*cmd, ir::eventType(cmd->event), conditions); break;
                case CommandKind::When: {
                    auto inner = conditions;
                    inner.push_back(lowering.lowerOne(*cmd->cond));
                    run(cmd->body, inner, kill);
                    break;
                }
                case CommandKind::On: deaths_.push_back(cmd.get()); break;  // (the checker allows `death` only)
            }
        }
    }

    // An instance that is stopped emits no more at a rate; one that is killed creates
    // nothing at all (its objects die in their next update: instanceKill).
    void instanceEmission(int site) {
        for (Yield& y : k.yields) {
            if (y.index != site) continue;
            if (y.kind == YieldKind::EmitRate)
                y.value = k.op(Op::Mul, Type::f32(), {y.value, lowering.instanceFlag(core::kInstanceEmitting)});
            if (y.kind == YieldKind::EmitCount && !emits[static_cast<size_t>(site)].rate()) {
                ValueId killed = k.op(Op::Gt, Type::boolean(), {lowering.instanceFlag(core::kInstanceKilled), k.scalar(0)});
                y.value = k.op(Op::Select, Type::f32(), {killed, k.scalar(0), y.value});
            }
        }
    }

    core::DrawKind draw = core::DrawKind::Point;  // the object's draw command's
    int trail = 0;                                // a trail's points
    // (state of the walk)
    std::vector<const Command*> deaths_;
    bool dying_ = false;  // lowering an `on death` block
};

// An extern's value as the checker computed it (ExternDecl::*Evaluated), in the IR's four
// lanes: a number spread over all four, a bool 0 or 1.
std::array<float, 4> externLanes(const std::optional<ConstValue>& v, Type t) {
    std::array<float, 4> out{};
    if (!v) return out;
    for (size_t i = 0; i < 4; ++i) out[i] = v->type.width() == 1 ? v->v[0] : v->v[i];
    if (t.isBool()) out = {v->isTrue() ? 1.0f : 0.0f, 0, 0, 0};
    return out;
}

// Events (`notify "hit"(…)`): a type each, after the program's, whose objects live until
// the end of the next step's update — `seen = false -> true; kill when prev(seen)` — so a
// host finds a step's events alive after it, and only them.
void lowerEvents(Module& m, const ast::Program& program, const Locator& locate) {
    for (const ast::Program::Event& e : program.events) {
        Object o;
        o.name = ir::eventType(e.name);
        o.loc = locate(e.range);
        for (size_t v = 0; v < e.types.size(); ++v) o.params.push_back({fmt::format("value{}", v), irType(e.types[v])});
        if (program.instanced) o.params.push_back({std::string(core::kInstanceParam), Type::f32()});
        Kernel k;
        k.kind = KernelKind::Behaviour;
        LocScope at(k, o.loc);
        int sites = 0;
        ObjectLowering lowering(m, locate, k, &o, nullptr, nullptr, sites);
        ValueId seen = lowering.temporal(Op::FollowedBy, Type::boolean(), {k.boolean(false), k.boolean(true)});
        k.yields.push_back({YieldKind::Kill, 0, 0, lowering.temporal(Op::Prev, Type::boolean(), {seen})});
        o.kernels.push_back(std::move(k));
        m.objects.push_back(std::move(o));
    }
}

}  // namespace

ir::Module lowerProgram(const ast::Program& program, const SourceManager& sources) {
    Module m;
    for (int f = 0; f < sources.count(); ++f) m.files.push_back(sources.file(f).path());
    Locator locate(sources);
    // Externs first: kernels refer to them by index.
    for (auto& module : program.modules)
        for (auto& d : module->decls)
            if (d->kind == DeclKind::Extern) {
                auto& e = static_cast<const ExternDecl&>(*d);
                Extern x{e.name, irType(e.type.type), {}, externLanes(e.defaultEvaluated, irType(e.type.type)), {}, {}};
                if (e.type.spelling == "color" || e.type.spelling == "point") x.spelling = e.type.spelling;
                if (e.rangeLow) {
                    x.low = externLanes(e.lowEvaluated, x.type);
                    x.high = externLanes(e.highEvaluated, x.type);
                }
                m.externs.push_back(x);
            }
    // An instanced program's start takes the instance it plays (and kernels read their
    // externs from its record: Module::instanced, from here on).
    if (program.instanced) m.start.params.push_back({std::string(core::kInstanceParam), Type::f32()});

    // Objects, parents before children; nested objects get qualified names.
    std::map<const ObjectDecl*, std::string> names;
    std::function<std::string(const ObjectDecl*)> qualified = [&](const ObjectDecl* o) -> std::string {
        if (!o) return "";
        if (auto it = names.find(o); it != names.end()) return it->second;
        return names[o] = o->parent ? qualified(o->parent) + "." + o->name : o->name;
    };
    // Attributes: the file's, then each enclosing object's, then the object's own.
    auto apply = [&](const ast::Attribute& a, Attributes& attributes) {
        if (a.name == "texture" && a.text) {
            attributes.texture = besideSource(sources, a.textRange, *a.text).string();
            if (a.value) {  // the checker's columns and rows
                attributes.textureColumns = static_cast<int>(a.value->v[0]);
                attributes.textureRows = static_cast<int>(a.value->v[1]);
            }
            return;
        }
        if (a.args.empty()) return;
        if (a.name == "integrator" && a.args[0]->kind == ExprKind::Name) {
            attributes.integrator = core::integratorFromName(static_cast<const NameExpr&>(*a.args[0]).name);
            attributes.integratorLoc = locate(a.args[0]->range);
        } else if (a.name == "precision" && a.args[0]->kind == ExprKind::Name) {
            attributes.precision = core::precisionFromName(static_cast<const NameExpr&>(*a.args[0]).name).value_or(core::Precision::Float);
        } else if ((a.name == "shape" || a.name == "blend") && a.args[0]->kind == ExprKind::Name) {
            const std::string& name = static_cast<const NameExpr&>(*a.args[0]).name;
            if (a.name == "shape") attributes.shape = core::shapeFromName(name);
            else attributes.blend = core::blendFromName(name);
        } else if (a.value) {  // the checker's value of @step or @capacity
            if (a.name == "step") attributes.step = a.value->v[0];
            if (a.name == "tolerance") {
                attributes.tolerance = a.value->v[0];
                attributes.toleranceOver = a.value->v[1];
            }
            if (a.name == "capacity") attributes.capacity = static_cast<uint64_t>(a.whole.value_or(a.value->v[0]));
        }
    };
    std::vector<std::pair<const ObjectDecl*, Attributes>> decls;
    std::function<void(const ObjectDecl&, Attributes)> collect = [&](const ObjectDecl& o, Attributes attributes) {
        for (auto& a : o.attributes) apply(a, attributes);
        decls.push_back({&o, attributes});
        for (auto& child : o.children) collect(*child, attributes);
    };
    for (auto& module : program.modules) {
        Attributes fileAttributes;
        for (auto& d : module->decls)
            if (d->kind == DeclKind::Attribute) apply(static_cast<const FileAttributeDecl&>(*d).attribute, fileAttributes);
        for (auto& d : module->decls)
            if (d->kind == DeclKind::Object) collect(static_cast<const ObjectDecl&>(*d), fileAttributes);
    }
    // Every object exists before any kernel is lowered: emits name their targets.
    for (auto& [decl, attributes] : decls) {
        Object o;
        o.name = qualified(decl);
        o.loc = locate(decl->nameRange);
        o.parent = qualified(decl->parent);
        o.attributes = attributes;
        for (auto& p : decl->params) o.params.push_back({p.name, irType(p.type.type)});
        if (program.instanced) o.params.push_back({std::string(core::kInstanceParam), Type::f32()});
        m.objects.push_back(std::move(o));
    }
    lowerEvents(m, program, locate);
    for (size_t i = 0; i < decls.size(); ++i) {
        const ObjectDecl* decl = decls[i].first;
        Object& o = m.objects[i];
        Kernel k;
        k.kind = KernelKind::Behaviour;
        int sites = 0;
        ObjectLowering lowering(m, locate, k, &o, decl, nullptr, sites);
        lowering.qualify = qualified;
        lowering.lowerEquations();
        ValueId kill = k.boolean(false);
        CommandLowering commands(lowering, k, o.emits, program, qualified, true);
        commands.runObject(decl->commands, kill);
        o.draw = commands.draw;
        o.trail = commands.trail;
        lowering.flushDeferred();
        if (program.instanced) {  // an instance killed by the host takes its objects with it
            LocScope at(k, locate(decl->nameRange));
            ValueId killed = k.op(Op::Gt, Type::boolean(), {lowering.instanceFlag(core::kInstanceKilled), k.scalar(0)});
            kill = k.op(Op::Or, Type::boolean(), {kill, killed});
        }
        k.yields.push_back({YieldKind::Kill, 0, 0, kill});
        o.kernels.push_back(std::move(k));
    }

    // Triggers and the start of the system.
    for (auto& module : program.modules)
        for (auto& d : module->decls) {
            if (d->kind == DeclKind::Trigger) {
                auto& t = static_cast<const TriggerDecl&>(*d);
                Trigger trigger;
                trigger.name = t.name;
                for (auto& p : t.params) {
                    trigger.params.push_back({p.name, irType(p.type.type)});
                    if (p.type.spelling == "color" || p.type.spelling == "point") trigger.params.back().spelling = p.type.spelling;
                }
                if (program.instanced) trigger.params.push_back({std::string(core::kInstanceParam), Type::f32()});
                trigger.kernel.kind = KernelKind::Trigger;
                int sites = 0;
                ObjectLowering lowering(m, locate, trigger.kernel, nullptr, nullptr, &t, sites);
                ValueId kill = trigger.kernel.boolean(false);
                CommandLowering commands(lowering, trigger.kernel, trigger.emits, program, qualified, false);
                commands.run(t.commands, {}, kill);
                m.triggers.push_back(std::move(trigger));
            }
        }
    m.start.name = "start";
    m.start.kernel.kind = KernelKind::Start;
    int startSites = 0;
    ObjectLowering startLowering(m, locate, m.start.kernel, nullptr, nullptr, nullptr, startSites);
    for (auto& module : program.modules)
        for (auto& d : module->decls)
            if (d->kind == DeclKind::Spawn) {
                auto& s = static_cast<const SpawnDecl&>(*d);
                int site = static_cast<int>(m.start.emits.size());
                m.start.emits.push_back({qualified(s.targetDecl), EmitSite::When::Creation});
                m.start.kernel.yields.push_back({YieldKind::EmitCount, site, 0, m.start.kernel.scalar(1)});
                for (size_t i = 0; i < s.args.size(); ++i)
                    m.start.kernel.yields.push_back(
                        {YieldKind::EmitArg, site, static_cast<int>(i), startLowering.lowerOne(*s.args[i])});
                if (program.instanced)
                    m.start.kernel.yields.push_back(
                        {YieldKind::EmitArg, site, static_cast<int>(s.args.size()), startLowering.instance()});
            }
    return m;
}

}  // namespace psys::lower