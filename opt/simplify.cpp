// simplify: local rewriting to a fixpoint (thesis §4.3.8, "local optimization").
//
// Every rule here gives bit-for-bit the value of what it replaces, for every input
// (NaN, ±Inf and −0 included), so the program's output does not change:
//
//   constant folding        pure instructions on constants, computed by ir/evaluate —
//                           the same code the interpreter runs
//   x·1, x/1, x−(+0),       identities that hold in IEEE arithmetic. Not applied: x+0
//   x+(−0), −(−x), !!x      (−0+0 is +0), x·0 (NaN·0, Inf·0), x−x (Inf−Inf), x/x.
//   x/c → x·(1/c)           only when 1/c is exact (c a power of two): otherwise it
//                           changes the last bit (see docs/optimizer.md)
//   min(x,x), max(x,x),     select on a constant, select with equal branches,
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
//
// With relaxed maths (PassOptions::relaxed) also: x+0 → x (wrong only in the sign of a
// zero: −0+0 is +0) and x/c → x·(1/c) for any finite non-zero c (at most 2 ulp away).
#include <cmath>
#include <cstring>

#include "ir/evaluate.h"
#include "ir/printer.h"
#include "opt/passes.h"
#include "opt/rewrite.h"

namespace psys::opt {

using namespace ir;

namespace {

bool isConst(const Kernel& k, ValueId v) { return k.at(v).op == Op::Const; }

// Whether every component of constant `v` has exactly the bits of `x`.
bool constAll(const Kernel& k, ValueId v, float x) {
    const Inst& i = k.at(v);
    if (i.op != Op::Const || !i.type.isFloat()) return false;
    for (int c = 0; c < i.type.width; ++c)
        if (std::memcmp(&i.constant[static_cast<size_t>(c)], &x, sizeof x) != 0) return false;
    return true;
}

// 1/c exactly, when every component of the constant c is ± a power of two (and 1/c is a
// normal float).
std::optional<std::array<float, 4>> exactReciprocal(const Inst& c) {
    if (c.op != Op::Const || !c.type.isFloat()) return std::nullopt;
    std::array<float, 4> out{};
    for (int i = 0; i < c.type.width; ++i) {
        float x = c.constant[static_cast<size_t>(i)];
        int exponent = 0;
        float mantissa = std::frexp(x, &exponent);
        if (!std::isfinite(x) || std::fabs(mantissa) != 0.5f) return std::nullopt;
        float r = 1.0f / x;
        if (!std::isnormal(r) || r * x != 1.0f) return std::nullopt;
        out[static_cast<size_t>(i)] = r;
    }
    return out;
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

bool componentwise(Op op) {
    return (op >= Op::Add && op <= Op::Fract) || op == Op::Select;
}

struct Context {
    bool relaxed = false;
    std::vector<int> users;  // per old value: how many instructions and yields use it
    const Kernel* old = nullptr;
};

std::optional<ValueId> rule(Rewriter& rw, const Inst& old, const std::vector<ValueId>& ops, const Context& ctx) {
    Kernel& k = rw.to();
    auto at = [&](size_t i) -> const Inst& { return k.at(ops[i]); };
    Inst inst = old;
    inst.operands = ops;
    // Temporal instructions: only snapshot of something fixed at creation.
    if (old.op == Op::Snapshot && creationInvariant(k, ops[0])) return ops[0];
    if (isTemporal(old.op) || isInput(old.op)) return std::nullopt;

    if (isPure(old.op)) {
        bool allConst = !ops.empty();
        for (ValueId o : ops) allConst &= isConst(k, o);
        if (allConst) {
            std::vector<Value> values;
            std::vector<Type> types;
            for (ValueId o : ops) {
                values.push_back({k.at(o).constant, 0});
                types.push_back(k.at(o).type);
            }
            Value v = evaluate(inst, values.data(), types.data());
            return k.constant(inst.type, v.f);
        }
    }
    // If-floating: an operation on a choice between constants and a constant is a choice
    // between two constants.
    if (isPure(old.op) && ops.size() == 2 && old.op != Op::Select) {
        for (size_t s = 0; s < 2; ++s) {
            const Inst& sel = at(s);
            if (sel.op != Op::Select || !isConst(k, sel.operands[1]) || !isConst(k, sel.operands[2]) ||
                !isConst(k, ops[1 - s]))
                continue;
            ValueId cond = sel.operands[0], branches[2] = {sel.operands[1], sel.operands[2]}, other = ops[1 - s];
            ValueId folded[2];
            for (int b = 0; b < 2; ++b) {
                Inst f = inst;
                f.name.clear();
                f.operands[s] = branches[b];
                f.operands[1 - s] = other;
                Value values[2] = {{k.at(f.operands[0]).constant, 0}, {k.at(f.operands[1]).constant, 0}};
                Type types[2] = {k.at(f.operands[0]).type, k.at(f.operands[1]).type};
                folded[b] = k.constant(inst.type, evaluate(f, values, types).f);
            }
            return rw.emit({Op::Select, inst.type, {cond, folded[0], folded[1]}, 0, 0, {}, {}, ""});
        }
    }
    switch (old.op) {
        case Op::Mul:
            for (size_t i = 0; i < 2; ++i) {
                if (constAll(k, ops[i], 1.0f)) return ops[1 - i];
                if (constAll(k, ops[i], -1.0f)) return rw.emit({Op::Neg, inst.type, {ops[1 - i]}, 0, 0, {}, {}, ""});
            }
            // splat(a)·K, a finite and ≥ +0: lanes of K that are ±0 or ±1 need no multiplication.
            for (size_t i = 0; i < 2; ++i) {
                const Inst& s = at(1 - i);
                if (!inst.type.isVector() || at(i).op != Op::Const || s.op != Op::Splat) continue;
                ValueId a = s.operands[0];
                if (!finiteNonNegative(k, a)) continue;
                std::array<float, 4> constant = at(i).constant;
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
                    else if (c == -1) lanes.push_back(rw.emit({Op::Neg, Type::f32(), {a}, 0, 0, {}, {}, ""}));
                    else lanes.push_back(rw.emit({Op::Mul, Type::f32(), {a, k.scalar(c)}, 0, 0, {}, {}, ""}));
                }
                return rw.emit({Op::Compose, inst.type, lanes, 0, 0, {}, {}, ""});
            }
            break;
        case Op::Add:
            for (size_t i = 0; i < 2; ++i) {
                if (constAll(k, ops[i], -0.0f)) return ops[1 - i];
                if (ctx.relaxed && constAll(k, ops[i], 0.0f)) return ops[1 - i];
                if (at(i).op == Op::Neg) return rw.emit({Op::Sub, inst.type, {ops[1 - i], at(i).operands[0]}, 0, 0, {}, {}, ""});
            }
            // Lane by lane when that makes lanes constant: K + compose(…) with constant parts.
            for (size_t i = 0; i < 2; ++i) {
                const Inst& parts = at(1 - i);
                if (!inst.type.isVector() || at(i).op != Op::Const || parts.op != Op::Compose) continue;
                bool anyConstant = false, scalarParts = true;
                for (ValueId p : parts.operands) {
                    anyConstant |= isConst(k, p);
                    scalarParts &= k.at(p).type.width == 1;
                }
                if (!anyConstant || !scalarParts) continue;
                std::array<float, 4> constant = at(i).constant;
                std::vector<ValueId> laneParts = parts.operands;  // a copy: emitting may move instructions
                std::vector<ValueId> lanes;
                for (size_t l = 0; l < laneParts.size(); ++l) {
                    ValueId kl = k.scalar(constant[l]);
                    Inst add{Op::Add, Type::f32(), {kl, laneParts[l]}, 0, 0, {}, {}, ""};
                    auto folded = rule(rw, add, add.operands, ctx);
                    lanes.push_back(folded ? *folded : rw.emit(add));
                }
                return rw.emit({Op::Compose, inst.type, lanes, 0, 0, {}, {}, ""});
            }
            break;
        case Op::Sub:
            if (constAll(k, ops[1], 0.0f)) return ops[0];
            break;
        case Op::Div:
            if (constAll(k, ops[1], 1.0f)) return ops[0];
            if (auto r = exactReciprocal(at(1))) return rw.emit({Op::Mul, inst.type, {ops[0], k.constant(inst.type, *r)}, 0, 0, {}, {}, ""});
            if (ctx.relaxed && at(1).op == Op::Const) {
                std::array<float, 4> r{};
                bool ok = true;
                for (int c = 0; c < inst.type.width; ++c) {
                    float x = at(1).constant[static_cast<size_t>(c)];
                    ok &= std::isfinite(x) && x != 0 && std::isnormal(1.0f / x);
                    r[static_cast<size_t>(c)] = 1.0f / x;
                }
                if (ok) return rw.emit({Op::Mul, inst.type, {ops[0], k.constant(inst.type, r)}, 0, 0, {}, {}, ""});
            }
            break;
        case Op::Neg:
            if (at(0).op == Op::Neg) return at(0).operands[0];
            break;
        case Op::Not:
            if (at(0).op == Op::Not) return at(0).operands[0];
            break;
        case Op::Min: case Op::Max: case Op::And: case Op::Or:
            if (ops[0] == ops[1]) return ops[0];
            break;
        case Op::Select:
            if (at(0).op == Op::Not) return rw.emit({Op::Select, inst.type, {at(0).operands[0], ops[2], ops[1]}, 0, 0, {}, {}, ""});
            break;
        case Op::Extract: {
            const Inst& v = at(0);
            if (v.op == Op::Splat) return v.operands[0];
            // Narrowing: only this lane of a componentwise vector operation is used.
            if (componentwise(v.op) && v.type.isVector() && ctx.users[old.operands[0]] == 1) {
                Inst lane = v;  // a copy: emitting below may move the kernel's instructions
                lane.type = Type::f32();
                lane.name.clear();
                for (size_t i = 0; i < lane.operands.size(); ++i) {
                    ValueId o = lane.operands[i];
                    if (lane.op == Op::Select && i == 0) continue;  // the condition is a bool
                    lane.operands[i] = rw.emit({Op::Extract, Type::f32(), {o}, inst.attr, 0, {}, {}, ""});
                }
                return rw.emit(std::move(lane));
            }
            if (v.op == Op::Shuffle)
                return rw.emit({Op::Extract, inst.type, {v.operands[0]}, v.lanes.at(static_cast<size_t>(inst.attr)), 0, {}, {}, ""});
            if (v.op == Op::Compose) {
                int lane = inst.attr;
                for (ValueId part : v.operands) {
                    int w = k.at(part).type.width;
                    if (lane < w) {
                        if (w == 1) return part;
                        return rw.emit({Op::Extract, inst.type, {part}, lane, 0, {}, {}, ""});
                    }
                    lane -= w;
                }
            }
            break;
        }
        case Op::Shuffle: {
            const Inst& v = at(0);
            if (v.op == Op::Splat) {
                if (inst.type.width == 1) return v.operands[0];
                return rw.emit({Op::Splat, inst.type, {v.operands[0]}, 0, 0, {}, {}, ""});
            }
            bool identity = static_cast<int>(inst.lanes.size()) == v.type.width;
            for (size_t i = 0; i < inst.lanes.size(); ++i) identity &= inst.lanes[i] == i;
            if (identity) return ops[0];
            break;
        }
        case Op::Compose: {
            // compose(v.x, v.y, v.z) of a vec3 v is v
            ValueId source = 0;
            bool same = true;
            for (size_t i = 0; i < ops.size() && same; ++i) {
                const Inst& part = at(i);
                same = part.op == Op::Extract && part.attr == static_cast<int>(i) && (i == 0 || part.operands[0] == source);
                if (same) source = part.operands[0];
            }
            if (same && k.at(source).type == inst.type) return source;
            break;
        }
        default: break;
    }
    return std::nullopt;
}

void simplifyKernel(Kernel& kernel, bool relaxed) {
    for (int round = 0; round < 16; ++round) {
        std::string before = print(kernel);
        Context ctx;
        ctx.relaxed = relaxed;
        ctx.users.assign(kernel.size(), 0);
        for (const Inst& i : kernel.insts())
            for (ValueId o : i.operands) ++ctx.users[o];
        for (const Yield& y : kernel.yields) ++ctx.users[y.value];
        for (auto& [name, v] : kernel.equations) ++ctx.users[v];
        Rewriter rw(kernel);
        Kernel next = rw.run([&ctx](Rewriter& r, ValueId, const Inst& inst, const std::vector<ValueId>& ops) {
            return rule(r, inst, ops, ctx);
        });
        next.kind = kernel.kind;
        next.site = kernel.site;
        kernel = std::move(next);
        bool changed = print(kernel) != before;
        if (!changed) break;
    }
}

}  // namespace

void simplify(Module& module, const PassOptions& options, PassErrors&) {
    for (Object& o : module.objects)
        for (Kernel& k : o.kernels) simplifyKernel(k, options.relaxed);
    for (Trigger& t : module.triggers) simplifyKernel(t.kernel, options.relaxed);
    simplifyKernel(module.start.kernel, options.relaxed);
}

}  // namespace psys::opt
