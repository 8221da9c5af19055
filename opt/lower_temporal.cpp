// lower-temporal: the thesis's behaviours become explicit state (thesis §3.3.7, §4.3.6).
//
// Each object's behaviour is evaluated at creation (`first` is true) and at every update
// after (`first` is false, `dt` is the update's length). Every temporal construct gets
// what it needs:
//
//   integrate(e)   slot A, starting at 0:     value = first ? 0 : A + e·dt    next A = value
//   derive(e)      slot P, starting at e:     value = first || dt <= 0 ? 0 : (e − P)/dt
//                                                                             next P = e
//   prev(e)        slot P, starting at e:     value = first ? 0 : P           next P = e
//   snapshot(e)    slot S, starting at e:     value = first ? e : S           next S = value
//   a -> b         no state:                  value = first ? a : b
//
// `A`, `P` and `S` read the slot as it was before this update. This is Euler's method
// evaluated in the order lowering chose: an integrand reads this update's values of what
// was evaluated before it and the previous update's value of what closes a cycle (which
// resolve-cycles made a `prev`), so a velocity integrated from an acceleration that reads
// the previous velocity, and a position integrated from that new velocity, is the
// semi-implicit Euler step games use. Other methods (midpoint, RK4) integrate an
// object's integrals together and will slot in here as further cases of `integrate`.
// With relaxed maths, the integral of something fixed at creation is c·age, no state.
#include <map>
#include <set>

#include <fmt/format.h>

#include "opt/passes.h"
#include "opt/rewrite.h"

namespace psys::opt {

using namespace ir;

namespace {

ValueId input(Kernel& k, Op op, Type t, int attr = 0) {
    Inst inst;
    inst.op = op;
    inst.type = t;
    inst.attr = attr;
    return k.add(std::move(inst));
}

ValueId broadcast(Kernel& k, ValueId scalar, Type t) {
    return t.width == 1 ? scalar : k.op(Op::Splat, t, {scalar});
}

// State slot names that say where the state is and survive edits elsewhere in the
// source (hot reload carries state by slot name): `integrate@vel` for the integral in
// equation vel, `prev@pos,vel#2` for the second prev of the tuple equation (pos, vel);
// `integrate#3` (the call site) for one outside every equation.
std::map<ValueId, std::string> slotNames(const Kernel& k) {
    // The equations, in evaluation order; a tuple's components share one name.
    std::map<ValueId, std::string> roots;
    for (auto& [name, v] : k.equations)
        if (!isLeaf(k.at(v).op)) roots[v] = roots.count(v) ? roots[v] + "," + name : name;
    std::map<ValueId, std::string> owner;
    for (auto& [root, name] : roots) {
        std::vector<ValueId> work = {root};
        std::set<ValueId> seen;
        while (!work.empty()) {
            ValueId v = work.back();
            work.pop_back();
            if (!seen.insert(v).second || (v != root && roots.count(v))) continue;
            if (isTemporal(k.at(v).op) && !owner.count(v)) owner[v] = name;
            for (ValueId o : k.at(v).operands) work.push_back(o);
        }
    }
    std::map<ValueId, std::string> names;
    std::map<std::string, int> seenKinds;
    for (ValueId v = 0; v < k.size(); ++v) {
        const Inst& i = k.at(v);
        if (!isTemporal(i.op)) continue;
        std::string kind(opInfo(i.op).name);
        auto it = owner.find(v);
        if (it == owner.end()) {
            names[v] = fmt::format("{}#{}", kind, i.attr);
            continue;
        }
        std::string base = kind + "@" + it->second;
        int n = ++seenKinds[base];
        names[v] = n == 1 ? base : fmt::format("{}#{}", base, n);
    }
    return names;
}

}  // namespace

void lowerTemporal(Module& module, const PassOptions& options, PassErrors& errors) {
    for (Object& object : module.objects) {
        Kernel* behaviour = object.kernel(KernelKind::Behaviour);
        if (!behaviour) continue;
        Integrator method = object.attributes.integrator.value_or(options.integrator);
        if (method != Integrator::Euler) {
            Loc at = object.attributes.integrator ? object.attributes.integratorLoc : object.loc;
            errors.error(at, fmt::format("object {}: @integrator({}) is not implemented yet; euler is", object.name,
                                         core::integratorName(method)));
            continue;
        }
        std::vector<std::pair<int, ValueId>> nextOld;  // (slot, old value its next is)
        std::vector<std::pair<int, ValueId>> nextNew;  // (slot, new value)
        std::map<ValueId, std::string> names = slotNames(*behaviour);
        ValueId current = 0;
        auto addSlot = [&](const Inst& inst, StateInit init) {
            object.state.push_back({names.at(current), inst.type, init});
            return static_cast<int>(object.state.size() - 1);
        };
        Rewriter rewriter(*behaviour);
        Kernel lowered = rewriter.run([&](Rewriter& rw, ValueId old, const Inst& inst,
                                          const std::vector<ValueId>& ops) -> std::optional<ValueId> {
            if (inst.op != Op::Integrate && inst.op != Op::Derive && inst.op != Op::Prev &&
                inst.op != Op::Snapshot && inst.op != Op::FollowedBy)
                return std::nullopt;
            current = old;
            Kernel& k = rw.to();
            Type t = inst.type;
            ValueId first = input(k, Op::First, Type::boolean());
            ValueId zero = zeroOf(k, t);
            switch (inst.op) {
                case Op::Integrate: {
                    // Relaxed: the Euler sum of something fixed at creation is c·age, exact
                    // in real arithmetic; no state needed (docs/optimizer.md).
                    if (options.relaxed && creationInvariant(k, ops[0]))
                        return rw.emit(Inst::make(Op::Mul, t, {ops[0], broadcast(k, input(k, Op::Age, Type::f32()), t)}));
                    int slot = addSlot(inst, StateInit::Zero);
                    ValueId a = input(k, Op::StateRead, t, slot);
                    ValueId dt = broadcast(k, input(k, Op::Dt, Type::f32()), t);
                    ValueId step = k.op(Op::Add, t, {a, k.op(Op::Mul, t, {ops[0], dt})});
                    ValueId value = rw.emit(Inst::make(Op::Select, t, {first, zero, step}));
                    nextNew.push_back({slot, value});
                    return value;
                }
                case Op::Derive: {
                    int slot = addSlot(inst, StateInit::Next);
                    ValueId p = input(k, Op::StateRead, t, slot);
                    ValueId dtScalar = input(k, Op::Dt, Type::f32());
                    ValueId moving = k.op(Op::Gt, Type::boolean(), {dtScalar, k.scalar(0)});
                    ValueId slope = k.op(Op::Div, t, {k.op(Op::Sub, t, {ops[0], p}), broadcast(k, dtScalar, t)});
                    ValueId ready = k.op(Op::And, Type::boolean(), {k.op(Op::Not, Type::boolean(), {first}), moving});
                    nextNew.push_back({slot, ops[0]});
                    return rw.emit(Inst::make(Op::Select, t, {ready, slope, zero}));
                }
                case Op::Prev: {
                    int slot = addSlot(inst, StateInit::Next);
                    ValueId p = input(k, Op::StateRead, t, slot);
                    nextOld.push_back({slot, inst.operands[0]});  // may be defined later
                    return rw.emit(Inst::make(Op::Select, t, {first, zero, p}));
                }
                case Op::Snapshot: {
                    int slot = addSlot(inst, StateInit::Next);
                    ValueId s = input(k, Op::StateRead, t, slot);
                    ValueId value = rw.emit(Inst::make(Op::Select, t, {first, ops[0], s}));
                    nextNew.push_back({slot, value});
                    return value;
                }
                case Op::FollowedBy:
                    // The next side may refer forward only through a `prev`, which reads
                    // state: by now both operands exist.
                    return rw.emit(Inst::make(Op::Select, t, {first, ops[0], ops[1]}));
                default: return std::nullopt;
            }
        });
        for (auto& [slot, value] : nextNew) lowered.yields.push_back({YieldKind::StateNext, slot, 0, value});
        for (auto& [slot, old] : nextOld) lowered.yields.push_back({YieldKind::StateNext, slot, 0, rewriter.map(old)});
        *behaviour = std::move(lowered);
    }
}

}  // namespace psys::opt
