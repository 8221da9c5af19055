// lower-temporal: the thesis's behaviours become explicit state (thesis §3.3.7, §4.3.6).
//
// Each object's behaviour is evaluated at creation (`first` is true) and at every update
// after (`first` is false, `dt` is the update's length). Every temporal construct but the
// integrals gets what it needs, one instruction at a time:
//
//   derive(e)      slot P, starting at e:     value = first || dt <= 0 ? 0 : (e − P)/dt
//                                                                             next P = e
//   prev(e)        slot P, starting at e:     value = first ? 0 : P           next P = e
//   snapshot(e)    slot S, starting at e:     value = first ? e : S           next S = value
//   a -> b         no state:                  value = first ? a : b
//
// The integrals form one derivative system per object, lowered as a whole by the
// object's method (@integrator, else the pipeline's default):
//
//   semi_implicit  (the default) integrate(e): slot A, starting at 0,
//                  value = first ? 0 : A + e·dt, next A = value — Euler's step evaluated
//                  in the order lowering chose: an integrand reads this update's values
//                  of what was evaluated before it and the previous update's value of
//                  what closes a cycle (resolve-cycles made it a `prev`), so a velocity
//                  integrated from an acceleration that reads the previous velocity, and
//                  a position integrated from that new velocity, is the semi-implicit
//                  Euler step games use.
//   the others     every integral keeps slot A; the method computes all of an object's
//                  new values together from the start of the step and stages inside it
//                  (opt/integrate_step.h, opt/integrate_methods.h). A stage sees
//                  `derive(e)` as its value at the last update (a slot of its own).
//
// In both cases, for methods with a stability limit, a decay rate the compiler can see
// gets a compile-time warning when it is a constant beyond the limit, and an `unstable`
// yield that counts the updates beyond it (opt/integrate_stability.cpp).
// With relaxed maths, the integral of something fixed at creation is c·age, no state;
// and under the default method `c + integrate(e)` with c fixed at creation (snapshots,
// parameters, constants) is one integral that starts at c (slot `integrate@x.from-creation`,
// value = first ? c : A + e·dt): equal in real arithmetic, rounded differently, and c is
// no longer read every update (the fire's `pos = snapshot(ipos) + integrate(vel)`).
// Neither for an object under @precision(double), whose integrals stay its state, nor in
// a system that may be hot-reloaded (PassOptions::reloadable): a reload carries each
// integral by name, and neither form has it.
#include <algorithm>
#include <map>
#include <set>

#include <fmt/format.h>

#include "opt/integrate_methods.h"
#include "opt/integrate_step.h"
#include "opt/linear_part.h"
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


bool stageMethod(Integrator m) { return m != Integrator::SemiImplicit; }

// The equation an integral's slot name says it is in: `integrate@vel` → `vel`.
std::string equationOf(const std::string& slot) {
    size_t at = slot.find('@');
    if (at == std::string::npos) return slot;
    return slot.substr(at + 1, slot.find('#', at) - at - 1);
}

class ObjectLowering {
public:
    ObjectLowering(Object& object, const Kernel& behaviour, Integrator method, const PassOptions& options,
                   PassErrors& errors)
        : object_(object), from_(behaviour), method_(method), options_(options), errors_(errors),
          names_(slotNames(behaviour)), rewriter_(behaviour) {}

    Kernel run() {
        Kernel perUpdate = lowerPerUpdate();
        std::vector<DecayRate> rates = decayRates();
        if (!stageMethod(method_)) {
            addUnstable(perUpdate, rates);
            return perUpdate;
        }
        std::vector<ValueId> integrals;
        std::vector<int> slots;
        for (const Integral& i : integrals_) {
            integrals.push_back(rewriter_.map(i.old));
            slots.push_back(i.slot);
        }
        StepBuilder b(perUpdate, integrals, slots);
        for (auto& [derived, seen] : stageViews_) b.stageView(derived, seen);
        for (ValueId v : snapshotsOfFixed_) b.snapshotOfFixed(v);
        b.to().setLoc(object_.loc);
        leaf_ = [&b, this](ValueId old) { return b.at(b.startPoint(), rewriter_.map(old)); };
        b.run([&](StepBuilder& builder) { return solve(builder); });
        addUnstable(b.to(), rates);
        return b.take();
    }

private:
    struct Integral {
        ValueId old;  // the `integrate` of the behaviour
        int slot;
        std::optional<Coefficient> linear;
    };

    // Every construct becomes state (the table above) but, for the methods other than
    // the default, the integrals: they stay `integrate` instructions, with their slots.
    Kernel lowerPerUpdate() {
        if (closedForms() && !stageMethod(method_)) findFolds();
        Kernel lowered = rewriter_.run([&](Rewriter& rw, ValueId old, const Inst& inst,
                                           const std::vector<ValueId>& ops) -> std::optional<ValueId> {
            if (auto folded = folds_.find(old); folded != folds_.end() && folded->second.applied)
                return rw.map(folded->second.integral);  // c + integrate(e): the integral that starts at c
            if (inst.op != Op::Integrate && inst.op != Op::Derive && inst.op != Op::Prev &&
                inst.op != Op::Snapshot && inst.op != Op::FollowedBy)
                return std::nullopt;
            current_ = old;
            return lowerOne(rw, old, inst, ops);
        });
        for (auto& [slot, value] : nextNew_) lowered.yields.push_back({YieldKind::StateNext, slot, 0, value});
        for (auto& [slot, old] : nextOld_) lowered.yields.push_back({YieldKind::StateNext, slot, 0, rewriter_.map(old)});
        if (stageMethod(method_))
            for (const Integral& i : integrals_)
                lowered.yields.push_back({YieldKind::StateNext, i.slot, 0, rewriter_.map(i.old)});
        return lowered;
    }

    int addSlot(Type type, StateInit init, const std::string& suffix = "") {
        object_.state.push_back({names_.at(current_) + suffix, type, init});
        return static_cast<int>(object_.state.size() - 1);
    }

    std::optional<ValueId> lowerOne(Rewriter& rw, ValueId old, const Inst& inst, const std::vector<ValueId>& ops) {
        Kernel& k = rw.to();
        Type t = inst.type;
        ValueId first = input(k, Op::First, Type::boolean());
        ValueId zero = zeroOf(k, t);
        switch (inst.op) {
            case Op::Integrate: {
                // Relaxed: the integral of something fixed at creation is c·age, exact in
                // real arithmetic, whatever the method; no state needed (docs/optimizer.md).
                if (closedForms() && creationInvariant(k, ops[0]))
                    return rw.emit(Inst::make(Op::Mul, t, {ops[0], broadcast(k, input(k, Op::Age, Type::f32()), t)}));
                auto fold = std::find_if(folds_.begin(), folds_.end(), [old](auto& f) { return f.second.integral == old; });
                int slot = fold == folds_.end() ? addSlot(t, StateInit::Zero)
                                                : addSlot(t, StateInit::Next, ".from-creation");  // starts at c
                if (fold != folds_.end()) fold->second.applied = true;
                integrals_.push_back({old, slot, std::nullopt});
                if (stageMethod(method_)) return std::nullopt;  // the method lowers it (run)
                ValueId a = input(k, Op::StateRead, t, slot);
                ValueId dt = broadcast(k, input(k, Op::Dt, Type::f32()), t);
                ValueId step = k.op(Op::Add, t, {a, k.op(Op::Mul, t, {ops[0], dt})});
                ValueId start = fold == folds_.end() ? zero : atCreation(k, fold->second.start);
                ValueId value = rw.emit(Inst::make(Op::Select, t, {first, start, step}));
                nextNew_.push_back({slot, value});
                return value;
            }
            case Op::Derive: {
                int slot = addSlot(t, StateInit::Next);
                ValueId p = input(k, Op::StateRead, t, slot);
                ValueId dtScalar = input(k, Op::Dt, Type::f32());
                ValueId moving = k.op(Op::Gt, Type::boolean(), {dtScalar, k.scalar(0)});
                ValueId slope = k.op(Op::Div, t, {k.op(Op::Sub, t, {ops[0], p}), broadcast(k, dtScalar, t)});
                ValueId ready = k.op(Op::And, Type::boolean(), {k.op(Op::Not, Type::boolean(), {first}), moving});
                nextNew_.push_back({slot, ops[0]});
                ValueId value = rw.emit(Inst::make(Op::Select, t, {ready, slope, zero}));
                if (stageMethod(method_)) {
                    // A stage inside the step sees the derivative as of the last update.
                    int last = addSlot(t, StateInit::Next, ".last");
                    nextNew_.push_back({last, value});
                    stageViews_[value] = rw.emit(Inst::make(Op::Select, t, {first, zero, input(k, Op::StateRead, t, last)}));
                }
                return value;
            }
            case Op::Prev: {
                int slot = addSlot(t, StateInit::Next);
                ValueId p = input(k, Op::StateRead, t, slot);
                nextOld_.push_back({slot, inst.operands[0]});  // may be defined later
                return rw.emit(Inst::make(Op::Select, t, {first, zero, p}));
            }
            case Op::Snapshot: {
                int slot = addSlot(t, StateInit::Next);
                ValueId s = input(k, Op::StateRead, t, slot);
                ValueId value = rw.emit(Inst::make(Op::Select, t, {first, ops[0], s}));
                nextNew_.push_back({slot, value});
                if (creationInvariant(k, ops[0])) snapshotsOfFixed_.push_back(value);
                return value;
            }
            case Op::FollowedBy:
                // The next side may refer forward only through a `prev` or a `recur`,
                // which the rewriter patches: by now both operands exist.
                return rw.emit(Inst::make(Op::Select, t, {first, ops[0], ops[1]}));
            default: return std::nullopt;
        }
    }

    // `c + integrate(e)` (either order) where c is fixed once the object is created and
    // the integral is used nowhere else: the sum becomes one integral starting at c.
    struct Fold {
        ValueId integral, start;  // behaviour values
        bool applied = false;     // the integral was lowered starting at c (not as c·age)
    };
    void findFolds() {
        std::map<ValueId, int> uses;
        for (ValueId v = 0; v < from_.size(); ++v)
            for (ValueId o : from_.at(v).operands) ++uses[o];
        for (const Yield& y : from_.yields) ++uses[y.value];
        for (auto& [name, v] : from_.equations) ++uses[v];
        for (ValueId v = 0; v < from_.size(); ++v) {
            const Inst& add = from_.at(v);
            if (add.op != Op::Add || !add.type.isFloat()) continue;
            for (int side = 0; side < 2; ++side) {
                ValueId integral = add.operands[static_cast<size_t>(side)], start = add.operands[static_cast<size_t>(1 - side)];
                if (from_.at(integral).op == Op::Integrate && uses[integral] == 1 && fixedAtCreation(start)) {
                    folds_[v] = {integral, start};
                    break;
                }
            }
        }
    }
    // Whether a behaviour value is fixed once the object is created: constants,
    // parameters, snapshots of them, and pure operations of these.
    bool fixedAtCreation(ValueId v) const {
        const Inst& i = from_.at(v);
        if (i.op == Op::Param || i.op == Op::Const) return true;
        if (i.op != Op::Snapshot && (!isPure(i.op) || isLeaf(i.op))) return false;
        for (ValueId o : i.operands)
            if (!fixedAtCreation(o)) return false;
        return true;
    }
    // A fixed behaviour value as it is at creation, built in `k`: a snapshot is its operand then.
    ValueId atCreation(Kernel& k, ValueId v) {
        const Inst& i = from_.at(v);
        if (i.op == Op::Snapshot) return atCreation(k, i.operands[0]);
        if (i.operands.empty() && rewriter_.visited(v)) return rewriter_.map(v);
        // Rebuilt without its snapshots (so it reads no snapshot's slot); simplify merges
        // what it repeats.
        Inst copy = i;
        for (ValueId& o : copy.operands) o = atCreation(k, o);
        return k.add(std::move(copy));
    }

    // The decay rate of each integral whose derivative has a linear part in it.
    std::vector<DecayRate> decayRates() {
        std::vector<DecayRate> rates;
        for (Integral& i : integrals_) {
            i.linear = linearPart(from_, from_.at(i.old).operands[0], i.old, !stageMethod(method_));
            if (!i.linear) continue;
            Coefficient k{Coefficient::Kind::Neg, i.linear->type, 0, {*i.linear}};
            DecayRate r;
            r.equation = equationOf(names_.at(i.old));
            r.loc = from_.at(i.old).loc;
            r.constant = constantValue(k, from_);
            r.build = [this, k] { return build(k, *target_, leaf_); };
            rates.push_back(std::move(r));
        }
        return rates;
    }

    void addUnstable(Kernel& k, std::vector<DecayRate>& rates) {
        target_ = &k;
        if (!stageMethod(method_)) leaf_ = [this](ValueId old) { return rewriter_.map(old); };
        if (auto flag = stabilityCheck(k, object_.name, method_, object_.attributes.step, rates, errors_))
            k.yields.push_back({YieldKind::Unstable, 0, 0, *flag});
    }

    std::vector<ValueId> solve(StepBuilder& b) {
        target_ = &b.to();
        switch (method_) {
            case Integrator::Exponential: {
                std::vector<bool> linear;
                for (const Integral& i : integrals_) linear.push_back(i.linear.has_value());
                return exponentialEuler(b, linear, [&](size_t j) { return build(*integrals_[j].linear, b.to(), leaf_); });
            }
            case Integrator::Exact: {
                std::vector<std::string> equations;
                for (const Integral& i : integrals_) equations.push_back(equationOf(names_.at(i.old)));
                if (auto values = closedForm(b, object_.name, equations, errors_)) return *values;
                std::vector<ValueId> unchanged;  // an error was reported; the pipeline stops
                for (size_t j = 0; j < b.size(); ++j) unchanged.push_back(b.start(j));
                return unchanged;
            }
            case Integrator::Leapfrog: return leapfrog(b);
            case Integrator::Bs3: {
                // The step to try next, its own slot; the tolerance the object states, else
                // bs3's own (opt/integrate_adaptive.cpp).
                object_.state.push_back({"bs3@step", Type::f32(), StateInit::Zero});
                const Attributes& a = object_.attributes;
                float metres = a.tolerance > 0 ? a.tolerance : static_cast<float>(core::kBs3Tolerance);
                float seconds = a.tolerance > 0 && a.toleranceOver > 0 ? a.toleranceOver
                                                                       : static_cast<float>(core::kToleranceSeconds);
                return bogackiShampine(b, static_cast<int>(object_.state.size() - 1), metres / seconds,
                                       a.precision == core::Precision::Double);
            }
            default: return rungeKutta(b, method_, object_.attributes.precision == core::Precision::Double);
        }
    }

    // Relaxed maths' rewrites of integrals, but not for an object in double: c·age is
    // computed from the float age, which the object asked not to be held to.
    bool relaxed() const { return options_.relaxed && object_.attributes.precision != core::Precision::Double; }
    // c·age and the integral that starts at c: not where a reload must find each
    // integral as a slot of its own (PassOptions::reloadable).
    bool closedForms() const { return relaxed() && !options_.reloadable; }

    Object& object_;
    const Kernel& from_;
    Integrator method_;
    const PassOptions& options_;
    PassErrors& errors_;
    std::map<ValueId, std::string> names_;
    Rewriter rewriter_;
    ValueId current_ = 0;
    std::vector<Integral> integrals_;
    std::vector<std::pair<int, ValueId>> nextNew_;  // (slot, new value)
    std::vector<std::pair<int, ValueId>> nextOld_;  // (slot, old value its next is)
    std::map<ValueId, ValueId> stageViews_;         // (derive, what a stage sees), new values
    std::vector<ValueId> snapshotsOfFixed_;         // snapshots of what is fixed at creation
    std::map<ValueId, Fold> folds_;                 // by the behaviour's `+`
    Kernel* target_ = nullptr;                      // where decay rates are built
    std::function<ValueId(ValueId)> leaf_;          // a behaviour value there
};

}  // namespace

Integrator methodOf(const Object& object, const PassOptions& options) {
    return options.everyObject.value_or(object.attributes.integrator.value_or(options.integrator));
}

void lowerTemporal(Module& module, const PassOptions& options, PassErrors& errors) {
    for (Object& object : module.objects) {
        Kernel* behaviour = object.kernel(KernelKind::Behaviour);
        if (!behaviour) continue;
        Integrator method = methodOf(object, options);
        Kernel lowered = ObjectLowering(object, *behaviour, method, options, errors).run();
        *behaviour = std::move(lowered);
    }
}

}  // namespace psys::opt
