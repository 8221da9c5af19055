// simplify: local rewriting to a fixpoint (thesis §4.3.8, "local optimization").
//
// Every rule here gives bit-for-bit the value of what it replaces, for every input
// (NaN, ±Inf and −0 included), so the program's output does not change. The rules are
// declarative patterns (opt/pattern.h) where a pattern can say them, and procedural
// patterns for the rest:
//
//   constant folding        pure instructions on constants, computed by ir/evaluate —
//                           the same code the interpreter runs
//   x·1, x/1, x−(+0),       identities that hold in IEEE arithmetic. Not applied: x+0
//   x+(−0), −(−x), !!x      (−0+0 is +0), x·0 (NaN·0, Inf·0), x−x (Inf−Inf), x/x.
//   x/c → x·(1/c)           only when 1/c is exact (c a power of two): otherwise it
//                           changes the last bit (see docs/optimizer.md)
//   min(x,x), max(x,x),     select on a constant, select with equal branches (opt/rewrite),
//   x&&x, x||x              select(!c, a, b) → select(c, b, a)
//   vectors                 extract of compose / splat / shuffle, shuffles and composes
//                           that rebuild a vector unchanged, shuffles of a splat
//   snapshot(x)             → x when x depends only on parameters and constants: it
//                           cannot change after creation, so it needs no state
//   x·(−1) → −x             exact in IEEE arithmetic
//   if-floating             f(select(c, k1, k2), k3) → select(c, f(k1, k3), f(k2, k3)) for
//                           constants k (thesis §4.3.7): the branches then fold
//   narrowing               one lane of a componentwise operation used by nothing else is
//                           that operation on that lane: extract(u+v, 1) → u.y + v.y
//   lane splitting          splat(a)·K with K a constant vector, some of whose lanes are
//                           ±0 or ±1, and `a` known finite and ≥ 0 (age, dt): each lane
//                           alone, a·(±0) = ±0 exactly; then K2 + compose(…) lane by lane,
//                           folding what became constant: mix(green, black, age) is
//                           (0, 1 − age, 0, 1), one operation instead of eight
//   x + (−y) → x − y        exact
//   yield kill = false      dropped: nothing dies (an object with no `kill` command), so
//                           no backend writes kill flags nor counts them, and the
//                           run-time has nothing to wait for
//
// With relaxed maths (PassOptions::relaxed) also: x+0 → x (wrong only in the sign of a
// zero: −0+0 is +0) and x/c → x·(1/c) for any finite non-zero c (at most 2 ulp away).
//
// The rules are tried in the order they are listed; a round rebuilds the kernel once,
// applying the first rule that matches each instruction, and rounds repeat until one
// fires no rule.
#include <algorithm>
#include <cmath>

#include "ir/evaluate.h"
#include "opt/passes.h"
#include "opt/pattern.h"
#include "opt/rewrite.h"

namespace psys::opt {

using namespace ir;

namespace {

bool isConst(const Kernel& k, ValueId v) { return k.at(v).op == Op::Const; }

// 1/c is exact: every lane of the constant c is ± a power of two and 1/c a normal float.
bool exactReciprocal(const Kernel& k, ValueId v) {
    const Inst& c = k.at(v);
    if (c.op != Op::Const || !c.type.isFloat()) return false;
    for (int i = 0; i < c.type.width; ++i) {
        float x = c.constant[static_cast<size_t>(i)];
        int exponent = 0;
        float mantissa = std::frexp(x, &exponent);
        if (!std::isfinite(x) || std::fabs(mantissa) != 0.5f) return false;
        float r = 1.0f / x;
        if (!std::isnormal(r) || r * x != 1.0f) return false;
    }
    return true;
}

// 1/c is a normal float for every lane (relaxed maths: not necessarily exact).
bool normalReciprocal(const Kernel& k, ValueId v) {
    const Inst& c = k.at(v);
    if (c.op != Op::Const || !c.type.isFloat()) return false;
    for (int i = 0; i < c.type.width; ++i) {
        float x = c.constant[static_cast<size_t>(i)];
        if (!std::isfinite(x) || x == 0 || !std::isnormal(1.0f / x)) return false;
    }
    return true;
}

// Known to be finite and ≥ +0 (never −0): ages and step lengths (the run-time refuses a
// negative or non-finite dt), and such constants.
bool finiteNonNegative(const Kernel& k, ValueId v) {
    const Inst& i = k.at(v);
    if (i.op == Op::Age || i.op == Op::Dt) return true;
    if (i.op == Op::Const && i.type.isScalarFloat()) {
        float x = i.constant[0];
        return std::isfinite(x) && x >= 0 && !std::signbit(x);
    }
    return false;
}

// What the procedural patterns need to know about the instruction being rewritten.
struct Context {
    bool relaxed = false;
    bool pairs = false;      // the behaviour of an object in double: pairedOp ops are not folded
    std::vector<int> users;  // per old value: how many instructions, yields and equations use it
    ValueId oldOperand0 = 0; // the old value of the current instruction's first operand
};

Value constantValue(const Kernel& k, ValueId v) { return {k.at(v).constant, 0}; }

// Pure instructions on constants, computed as the interpreter would.
std::optional<ValueId> foldConstants(Rewriter& rw, const Inst& inst) {
    Kernel& k = rw.to();
    if (!isPure(inst.op) || inst.operands.empty()) return std::nullopt;
    std::vector<Value> values;
    std::vector<Type> types;
    for (ValueId o : inst.operands) {
        if (!isConst(k, o)) return std::nullopt;
        values.push_back(constantValue(k, o));
        types.push_back(k.at(o).type);
    }
    return k.constant(inst.type, evaluate(inst, values.data(), types.data()).f);
}

// f(select(c, k1, k2), k3) → select(c, f(k1, k3), f(k2, k3)) for constants k.
std::optional<ValueId> floatIf(Rewriter& rw, const Inst& inst) {
    Kernel& k = rw.to();
    if (!isPure(inst.op) || inst.operands.size() != 2) return std::nullopt;
    for (size_t s = 0; s < 2; ++s) {
        const Inst& sel = k.at(inst.operands[s]);
        ValueId other = inst.operands[1 - s];
        if (sel.op != Op::Select || !isConst(k, sel.operands[1]) || !isConst(k, sel.operands[2]) || !isConst(k, other))
            continue;
        ValueId cond = sel.operands[0], branches[2] = {sel.operands[1], sel.operands[2]};
        ValueId folded[2];
        for (int b = 0; b < 2; ++b) {
            Inst f = Inst::make(inst.op, inst.type, inst.operands, inst.attr, inst.attr2);
            f.operands[s] = branches[b];
            f.operands[1 - s] = other;
            Value values[2] = {constantValue(k, f.operands[0]), constantValue(k, f.operands[1])};
            Type types[2] = {k.at(f.operands[0]).type, k.at(f.operands[1]).type};
            folded[b] = k.constant(inst.type, evaluate(f, values, types).f);
        }
        return rw.emit(Inst::make(Op::Select, inst.type, {cond, folded[0], folded[1]}));
    }
    return std::nullopt;
}

// splat(a)·K, a finite and ≥ +0: lanes of K that are ±0 or ±1 need no multiplication.
std::optional<ValueId> splitMulLanes(Rewriter& rw, const Inst& inst) {
    Kernel& k = rw.to();
    if (!inst.type.isVector()) return std::nullopt;
    for (size_t i = 0; i < 2; ++i) {
        const Inst& s = k.at(inst.operands[1 - i]);
        if (k.at(inst.operands[i]).op != Op::Const || s.op != Op::Splat) continue;
        ValueId a = s.operands[0];
        if (!finiteNonNegative(k, a)) continue;
        std::array<float, 4> constant = k.at(inst.operands[i]).constant;
        bool special = false;
        for (int l = 0; l < inst.type.width; ++l) {
            float c = constant[static_cast<size_t>(l)];
            special |= c == 0 || c == 1 || c == -1;
        }
        if (!special) continue;
        std::vector<ValueId> lanes;
        for (int l = 0; l < inst.type.width; ++l) {
            float c = constant[static_cast<size_t>(l)];
            if (c == 0) lanes.push_back(k.scalar(c));  // a·(±0) is ±0 for finite a ≥ +0
            else if (c == 1) lanes.push_back(a);
            else if (c == -1) lanes.push_back(rw.emit(Inst::make(Op::Neg, Type::f32(), {a})));
            else lanes.push_back(rw.emit(Inst::make(Op::Mul, Type::f32(), {a, k.scalar(c)})));
        }
        return rw.emit(Inst::make(Op::Compose, inst.type, lanes));
    }
    return std::nullopt;
}

// K + compose(scalars…) lane by lane, when some of the parts are constants (each lane's
// sum goes through every rule again, so constant lanes fold).
std::optional<ValueId> splitAddLanes(Rewriter& rw, const Inst& inst, const Rules& rules, bool relaxed) {
    Kernel& k = rw.to();
    if (!inst.type.isVector()) return std::nullopt;
    for (size_t i = 0; i < 2; ++i) {
        const Inst& parts = k.at(inst.operands[1 - i]);
        if (k.at(inst.operands[i]).op != Op::Const || parts.op != Op::Compose) continue;
        bool anyConstant = false, scalarParts = true;
        for (ValueId p : parts.operands) {
            anyConstant |= isConst(k, p);
            scalarParts &= k.at(p).type.width == 1;
        }
        if (!anyConstant || !scalarParts) continue;
        std::array<float, 4> constant = k.at(inst.operands[i]).constant;
        std::vector<ValueId> laneParts = parts.operands;  // a copy: emitting may move instructions
        std::vector<ValueId> lanes;
        for (size_t l = 0; l < laneParts.size(); ++l) {
            Inst add = Inst::make(Op::Add, Type::f32(), {k.scalar(constant[l]), laneParts[l]});
            auto folded = rules.apply(rw, add, relaxed, nullptr);
            lanes.push_back(folded ? *folded : rw.emit(add));
        }
        return rw.emit(Inst::make(Op::Compose, inst.type, lanes));
    }
    return std::nullopt;
}

// Only this lane of a componentwise vector operation is used: the operation on that lane.
std::optional<ValueId> narrow(Rewriter& rw, const Inst& inst, const Context& ctx) {
    Kernel& k = rw.to();
    const Inst& v = k.at(inst.operands[0]);
    if (!isComponentwise(v.op) || !v.type.isVector() || ctx.users[ctx.oldOperand0] != 1) return std::nullopt;
    Inst lane = v;  // a copy: emitting below may move the kernel's instructions
    lane.type = Type::f32();
    lane.name.clear();
    lane.loc = {};
    for (size_t i = 0; i < lane.operands.size(); ++i) {
        if (lane.op == Op::Select && i == 0) continue;  // the condition is one bool
        lane.operands[i] = rw.emit(Inst::make(Op::Extract, Type::f32(), {lane.operands[i]}, inst.attr));
    }
    return rw.emit(std::move(lane));
}

// extract(shuffle(v, lanes), i) → extract(v, lanes[i]); extract(compose(…), i) → its part.
std::optional<ValueId> extractThrough(Rewriter& rw, const Inst& inst) {
    Kernel& k = rw.to();
    const Inst& v = k.at(inst.operands[0]);
    if (v.op == Op::Shuffle)
        return rw.emit(Inst::make(Op::Extract, inst.type, {v.operands[0]}, v.lanes.at(static_cast<size_t>(inst.attr))));
    if (v.op != Op::Compose) return std::nullopt;
    int lane = inst.attr;
    for (ValueId part : v.operands) {
        int w = k.at(part).type.width;
        if (lane < w) return w == 1 ? part : rw.emit(Inst::make(Op::Extract, inst.type, {part}, lane));
        lane -= w;
    }
    return std::nullopt;
}

// A shuffle of a splat is a splat (or the scalar); a shuffle that keeps every lane in
// place is its operand.
std::optional<ValueId> simplifyShuffle(Rewriter& rw, const Inst& inst) {
    Kernel& k = rw.to();
    const Inst& v = k.at(inst.operands[0]);
    if (v.op == Op::Splat) {
        if (inst.type.width == 1) return v.operands[0];
        return rw.emit(Inst::make(Op::Splat, inst.type, {v.operands[0]}));
    }
    bool identity = static_cast<int>(inst.lanes.size()) == v.type.width;
    for (size_t i = 0; i < inst.lanes.size(); ++i) identity &= inst.lanes[i] == i;
    if (identity) return inst.operands[0];
    return std::nullopt;
}

// compose(v.x, v.y, v.z) of a vec3 v is v.
std::optional<ValueId> composeOfExtracts(Rewriter& rw, const Inst& inst) {
    Kernel& k = rw.to();
    ValueId source = 0;
    for (size_t i = 0; i < inst.operands.size(); ++i) {
        const Inst& part = k.at(inst.operands[i]);
        if (part.op != Op::Extract || part.attr != static_cast<int>(i) || (i > 0 && part.operands[0] != source))
            return std::nullopt;
        source = part.operands[0];
    }
    if (k.at(source).type == inst.type) return source;
    return std::nullopt;
}

// The rules, in the order they are tried.
// The context of the kernel being simplified on this thread, for the procedural patterns.
thread_local const Context* current = nullptr;

const Rules& simplifyRules(const Context& ctx) {
    current = &ctx;
    static const Rules rules = [] {
        Rules r;
        Pat x = var(0), y = var(1), a = var(2), b = var(3);
        Pat c = constant(4);
        r.add(ProceduralPattern{"snapshot of what is fixed at creation", Op::Snapshot,
                                [](Rewriter& rw, const Inst& inst) -> std::optional<ValueId> {
                                    if (creationInvariant(rw.to(), inst.operands[0])) return inst.operands[0];
                                    return std::nullopt;
                                }});
        r.add(ProceduralPattern{"constant folding", Op::Const, [](Rewriter& rw, const Inst& inst) -> std::optional<ValueId> {
                                    // In pairs later (double-precision), not folded in float now.
                                    if (current->pairs && inst.type.isFloat() && pairedOp(inst.op)) return std::nullopt;
                                    return foldConstants(rw, inst);
                                }});
        r.add(ProceduralPattern{"if-floating", Op::Const, floatIf});
        r.add(rewrite("x * 1 → x", x * lit(1.0f), x));
        r.add(rewrite("x * -1 → -x", x * lit(-1.0f), -x));
        r.add(ProceduralPattern{"lane splitting: splat(a) * K", Op::Mul, splitMulLanes});
        r.add(rewrite("x + -0 → x", x + lit(-0.0f), x));
        r.add(rewrite("x + 0 → x", x + lit(0.0f), x, {}, true));
        r.add(rewrite("x + -y → x - y", x + (-y), x - y));
        r.add(ProceduralPattern{"lane splitting: K + compose(…)", Op::Add,
                                [&r](Rewriter& rw, const Inst& inst) { return splitAddLanes(rw, inst, r, current->relaxed); }});
        r.add(rewrite("x - 0 → x", x - lit(0.0f), x));
        r.add(rewrite("x / 1 → x", x / lit(1.0f), x));
        r.add(rewrite("x / c → x * (1/c), 1/c exact", x / c, x * (lit(1.0f) / c),
                      [](const Kernel& k, const Bindings& bound) { return exactReciprocal(k, bound[4]); }));
        r.add(rewrite("x / c → x * (1/c)", x / c, x * (lit(1.0f) / c),
                      [](const Kernel& k, const Bindings& bound) { return normalReciprocal(k, bound[4]); }, true));
        r.add(rewrite("-(-x) → x", -(-x), x));
        r.add(rewrite("!!x → x", !(!x), x));
        r.add(rewrite("min(x, x) → x", min(x, x), x));
        r.add(rewrite("max(x, x) → x", max(x, x), x));
        r.add(rewrite("x && x → x", both(x, x), x));
        r.add(rewrite("x || x → x", either(x, x), x));
        r.add(rewrite("select(!c, a, b) → select(c, b, a)", select(!y, a, b), select(y, b, a)));
        r.add(rewrite("extract(splat(x)) → x", extract(splat(x)), x));
        r.add(ProceduralPattern{"narrowing: one lane of a componentwise operation", Op::Extract,
                                [](Rewriter& rw, const Inst& inst) { return narrow(rw, inst, *current); }});
        r.add(ProceduralPattern{"extract through shuffle and compose", Op::Extract, extractThrough});
        r.add(ProceduralPattern{"shuffles of splats, identity shuffles", Op::Shuffle, simplifyShuffle});
        r.add(ProceduralPattern{"compose of a vector's lanes", Op::Compose, composeOfExtracts});
        return r;
    }();
    return rules;
}

// A kill that is constant false says nothing: it goes, and so does its constant.
void dropFalseKill(Kernel& kernel) {
    auto never = [&](const Yield& y) {
        const Inst& v = kernel.at(y.value);
        return y.kind == YieldKind::Kill && v.op == Op::Const && v.constant[0] == 0;
    };
    if (std::none_of(kernel.yields.begin(), kernel.yields.end(), never)) return;
    std::erase_if(kernel.yields, never);
    Rewriter rw(kernel);
    Kernel clean = rw.run(nullptr);
    clean.kind = kernel.kind;
    clean.site = kernel.site;
    kernel = std::move(clean);
}

void simplifyKernel(Kernel& kernel, bool relaxed, bool pairs = false) {
    for (int round = 0; round < 16; ++round) {
        Context ctx;
        ctx.relaxed = relaxed;
        ctx.pairs = pairs;
        ctx.users.assign(kernel.size(), 0);
        for (const Inst& i : kernel.insts())
            for (ValueId o : i.operands) ++ctx.users[o];
        for (const Yield& y : kernel.yields) ++ctx.users[y.value];
        for (auto& [name, v] : kernel.equations) ++ctx.users[v];
        const Rules& rules = simplifyRules(ctx);
        size_t fired = 0;
        Rewriter rw(kernel);
        Kernel next = rw.run([&](Rewriter& r, ValueId, const Inst& old, const std::vector<ValueId>& ops) {
            Inst inst = old;
            inst.operands = ops;
            ctx.oldOperand0 = old.operands.empty() ? 0 : old.operands[0];
            auto replaced = rules.apply(r, inst, relaxed, nullptr);
            fired += replaced.has_value();
            return replaced;
        });
        next.kind = kernel.kind;
        next.site = kernel.site;
        kernel = std::move(next);
        if (fired == 0) break;
    }
    dropFalseKill(kernel);
}

}  // namespace

void simplify(Module& module, const PassOptions& options, PassErrors&) {
    for (Object& o : module.objects)
        for (Kernel& k : o.kernels)
            simplifyKernel(k, options.relaxed,
                           o.attributes.precision == Precision::Double && k.kind == KernelKind::Behaviour);
    for (Trigger& t : module.triggers) simplifyKernel(t.kernel, options.relaxed);
    simplifyKernel(module.start.kernel, options.relaxed);
}

}  // namespace psys::opt
