// double-precision: an object under @precision(double) keeps its state as pairs of
// floats and computes what writes its state in pair arithmetic.
//
// Why pairs of floats and not doubles: every backend (the interpreter, LLVM, GLSL)
// computes IEEE single precision alike, bit for bit, so double arithmetic built in the IR
// out of float operations has one meaning everywhere and needs no code in any backend;
// a GPU with slow doubles (or none) runs it too. A value is hi + lo with |lo| ≤ ½ ulp(hi):
// 48 significant bits (a double has 53), a relative rounding of about 3.6e-15.
//
// The algorithms are the classical error-free transformations: Knuth's two-sum, Dekker's
// fast two-sum, and the exact product by Veltkamp's split (no fused multiply-add: exact
// maths contracts nothing on any backend, and GLSL's values are `precise`). A sum adds
// the high parts and the low parts with their errors, then renormalises (Joldes, Muller &
// Popescu 2017, "accurate" double-word addition); a product adds the cross terms to the
// exact product of the high parts; a quotient is corrected once by its remainder, a
// square root once by Newton's step. A pair whose low part is known to be 0 (a float)
// skips the work that would add 0.
//
// What is paired: state reads (the slot and its low part, the slot `name@lo`), constants
// and inputs (their low part 0: a number in the source, a parameter, the age and dt are
// floats), + − × ÷, negation, sqrt, whole powers 2 to 4, dot, the operations that move
// lanes, selects and comparisons. Any other function (sin, min, floor, …) is computed in
// float on the value rounded to float (the high part) and gives a float. Arithmetic on
// constants alone (`w * w`) is paired too: simplify does not fold those ops in such an
// object's behaviour (pairedOp), and folds the pair arithmetic after this pass, bit for
// bit, so a program means the same with the optimizer and without.
//
// Which kernels: those that write the object's state (init, update). Each write of a slot
// writes its low part too; every other kernel (render, exports, spawn) reads the high
// part, the value rounded to float, as a float object's kernels read its state.
//
// The pass runs after split-kernels (the integration method's arithmetic exists) and
// before anything that may reorder arithmetic; reassociate leaves these objects alone.
#include <cfloat>

#include "opt/passes.h"

namespace psys::opt {

using namespace ir;

namespace {

struct Pair {
    ValueId hi = 0, lo = 0;
    bool exact = true;  // lo is 0: the value is a float (or a bool, a u32)
};

class PairKernel {
public:
    PairKernel(const Kernel& from, const std::vector<int>& low) : from_(from), low_(low) {
        to_.kind = from.kind;
        to_.site = from.site;
        to_.storage = from.storage;
    }

    Kernel run() {
        pairs_.resize(from_.size());
        for (ValueId v = 0; v < from_.size(); ++v) {
            const Inst& inst = from_.at(v);
            LocScope at(to_, inst.loc);
            pairs_[v] = pair(inst);
        }
        for (const Yield& y : from_.yields) {
            const Pair& p = pairs_[y.value];
            to_.yields.push_back({y.kind, y.index, y.sub, p.hi});
            if (y.kind != YieldKind::StateNext || low_[static_cast<size_t>(y.index)] < 0) continue;
            LocScope at(to_, from_.at(y.value).loc);
            ValueId lo = p.exact ? zero(from_.at(y.value).type) : p.lo;
            to_.yields.push_back({YieldKind::StateNext, low_[static_cast<size_t>(y.index)], 0, lo});
        }
        for (const auto& [name, v] : from_.equations) to_.equations[name] = pairs_[v].hi;
        return std::move(to_);
    }

private:
    ValueId op(Op o, Type t, std::vector<ValueId> xs) { return to_.op(o, t, std::move(xs)); }
    ValueId splat(Type t, float v) { return to_.constant(t, {v, v, v, v}); }
    ValueId zero(Type t) { return splat(t, 0); }
    ValueId lo(const Pair& p, Type t) { return p.exact ? zero(t) : p.lo; }

    // Knuth's two-sum: s + e = a + b exactly, s = fl(a + b).
    Pair twoSum(Type t, ValueId a, ValueId b) {
        ValueId s = op(Op::Add, t, {a, b});
        ValueId bb = op(Op::Sub, t, {s, a});
        ValueId e = op(Op::Add, t, {op(Op::Sub, t, {a, op(Op::Sub, t, {s, bb})}), op(Op::Sub, t, {b, bb})});
        return {s, e, false};
    }
    // Dekker's fast two-sum: exact where |a| ≥ |b| (a renormalisation).
    Pair fastTwoSum(Type t, ValueId a, ValueId b) {
        ValueId s = op(Op::Add, t, {a, b});
        return {s, op(Op::Sub, t, {b, op(Op::Sub, t, {s, a})}), false};
    }
    // Veltkamp's split: a = h + l, each of 12 significant bits, so their products are exact.
    // 4097·a overflows past |a| ≈ 8.3e34 and made the pair NaN where float stays finite:
    // the multiplier reads a clamped to the largest it can take (0x1.ffcp115), so past it h
    // is close to a and l small, and the product keeps float's accuracy, finite (two
    // operations; scaling a by 2⁻¹³ instead lost the low part of every product below
    // 1e-34). The same bits as the plain split wherever that one is finite.
    std::pair<ValueId, ValueId> split(Type t, ValueId a) {
        const float most = 0x1.ffcp115f;
        ValueId clamped = op(Op::Max, t, {op(Op::Min, t, {a, splat(t, most)}), splat(t, -most)});
        ValueId c = op(Op::Mul, t, {splat(t, 4097.0f), clamped});
        ValueId h = op(Op::Sub, t, {c, op(Op::Sub, t, {c, a})});
        return {h, op(Op::Sub, t, {a, h})};
    }
    // Dekker's exact product: p + e = a·b exactly, p = fl(a·b).
    Pair twoProduct(Type t, ValueId a, ValueId b) {
        ValueId p = op(Op::Mul, t, {a, b});
        auto [ah, al] = split(t, a);
        auto [bh, bl] = split(t, b);
        ValueId e = op(Op::Sub, t, {op(Op::Mul, t, {ah, bh}), p});
        e = op(Op::Add, t, {e, op(Op::Mul, t, {ah, bl})});
        e = op(Op::Add, t, {e, op(Op::Mul, t, {al, bh})});
        e = op(Op::Add, t, {e, op(Op::Mul, t, {al, bl})});
        return {p, e, false};
    }

    Pair add(Type t, const Pair& x, const Pair& y) {
        Pair s = twoSum(t, x.hi, y.hi);
        if (x.exact && y.exact) return s;
        if (x.exact || y.exact) {
            ValueId e = op(Op::Add, t, {s.lo, x.exact ? y.lo : x.lo});
            return fastTwoSum(t, s.hi, e);
        }
        Pair l = twoSum(t, x.lo, y.lo);
        Pair r = fastTwoSum(t, s.hi, op(Op::Add, t, {s.lo, l.hi}));
        return fastTwoSum(t, r.hi, op(Op::Add, t, {r.lo, l.lo}));
    }
    Pair neg(Type t, const Pair& x) {
        return {op(Op::Neg, t, {x.hi}), x.exact ? x.lo : op(Op::Neg, t, {x.lo}), x.exact};
    }
    Pair mul(Type t, const Pair& x, const Pair& y) {
        Pair p = twoProduct(t, x.hi, y.hi);
        if (x.exact && y.exact) return p;
        ValueId e = p.lo;
        if (!y.exact) e = op(Op::Add, t, {e, op(Op::Mul, t, {x.hi, y.lo})});
        if (!x.exact) e = op(Op::Add, t, {e, op(Op::Mul, t, {x.lo, y.hi})});
        return fastTwoSum(t, p.hi, e);
    }
    // q = x/y in float, then the remainder x − q·y (exact in pairs) divided once more.
    Pair div(Type t, const Pair& x, const Pair& y) {
        ValueId q = op(Op::Div, t, {x.hi, y.hi});
        Pair r = add(t, x, neg(t, mul(t, y, {q, q, true})));
        return fastTwoSum(t, q, op(Op::Div, t, {r.hi, y.hi}));
    }
    // s = √x in float, then Newton's step s + (x − s²)/(2s). The smallest normal float
    // stands in for s = 0 (x = 0: the correction is 0/tiny = 0).
    Pair sqrt(Type t, const Pair& x) {
        ValueId s = op(Op::Sqrt, t, {x.hi});
        Pair r = add(t, x, neg(t, twoProduct(t, s, s)));
        ValueId twice = op(Op::Mul, t, {splat(t, 2.0f), op(Op::Max, t, {s, splat(t, FLT_MIN)})});
        return fastTwoSum(t, s, op(Op::Div, t, {r.hi, twice}));
    }
    // Lane l of a pair.
    Pair lane(const Pair& x, Type t, int l) {
        if (t.width == 1) return x;
        ValueId hi = to_.op(Op::Extract, Type::f32(), {x.hi}, l);
        return {hi, x.exact ? x.lo : to_.op(Op::Extract, Type::f32(), {x.lo}, l), x.exact};
    }
    // x < y and the others: on the high parts, then the low parts where those are equal.
    ValueId compare(Op o, const Pair& x, const Pair& y) {
        if (x.exact && y.exact) return op(o, Type::boolean(), {x.hi, y.hi});
        Type t = Type::f32();
        Op strict = o == Op::Le ? Op::Lt : o == Op::Ge ? Op::Gt : o;
        ValueId tie = op(Op::And, Type::boolean(),
                         {op(Op::Eq, Type::boolean(), {x.hi, y.hi}), op(o, Type::boolean(), {lo(x, t), lo(y, t)})});
        return op(Op::Or, Type::boolean(), {op(strict, Type::boolean(), {x.hi, y.hi}), tie});
    }

    // The same instruction on the high parts and on the low parts (lanes moved, selected).
    Pair onBoth(const Inst& inst, bool allExact) {
        Inst hi = inst;
        for (ValueId& o : hi.operands) o = pairs_[o].hi;
        ValueId h = to_.add(hi);
        if (allExact) return {h, h, true};
        Inst lo = inst;
        for (ValueId& o : lo.operands)
            o = from_.at(o).type.isFloat() ? this->lo(pairs_[o], from_.at(o).type) : pairs_[o].hi;
        return {h, to_.add(lo), false};
    }

    // The power a constant exponent gives as 2, 3 or 4 in every lane, else 0.
    int wholePower(ValueId exponent) const {
        const Inst& e = from_.at(exponent);
        if (e.op != Op::Const) return 0;
        float n = e.constant[0];
        for (int l = 1; l < e.type.width; ++l)
            if (e.constant[static_cast<size_t>(l)] != n) return 0;
        return n == 2 || n == 3 || n == 4 ? static_cast<int>(n) : 0;
    }

    Pair pair(const Inst& inst) {
        Type t = inst.type;
        auto x = [&](size_t n) -> const Pair& { return pairs_[inst.operands[n]]; };
        bool allExact = true;
        for (ValueId o : inst.operands) allExact &= pairs_[o].exact;
        switch (inst.op) {
            case Op::StateRead: {
                int low = inst.attr >= 0 && static_cast<size_t>(inst.attr) < low_.size() ? low_[static_cast<size_t>(inst.attr)] : -1;
                ValueId hi = to_.add(inst);
                if (low < 0) return {hi, hi, true};
                return {hi, to_.add(Inst::make(Op::StateRead, t, {}, low)), false};
            }
            case Op::Add: return add(t, x(0), x(1));
            case Op::Sub: return add(t, x(0), neg(t, x(1)));
            case Op::Mul: return mul(t, x(0), x(1));
            case Op::Div: return div(t, x(0), x(1));
            case Op::Neg: return neg(t, x(0));
            case Op::Sqrt: return sqrt(t, x(0));
            case Op::Pow:  // to a whole power 2 … 4 (an inverse square law's r³): products
                if (int n = wholePower(inst.operands[1]); n > 0) {
                    Pair p = x(0);
                    for (int i = 1; i < n; ++i) p = mul(t, p, x(0));
                    return p;
                }
                break;
            case Op::Dot: {
                Type lanes = from_.at(inst.operands[0]).type;
                Pair sum;
                for (int l = 0; l < lanes.width; ++l) {
                    Pair term = mul(Type::f32(), lane(x(0), lanes, l), lane(x(1), lanes, l));
                    sum = l == 0 ? term : add(Type::f32(), sum, term);
                }
                return sum;
            }
            case Op::Lt: case Op::Le: case Op::Gt: case Op::Ge: {
                ValueId c = compare(inst.op, x(0), x(1));
                return {c, c, true};
            }
            case Op::Eq: case Op::Ne: {
                if (allExact || !from_.at(inst.operands[0]).type.isFloat()) break;
                Type ft = from_.at(inst.operands[0]).type;
                ValueId equal = op(Op::And, Type::boolean(), {op(Op::Eq, Type::boolean(), {x(0).hi, x(1).hi}),
                                                              op(Op::Eq, Type::boolean(), {lo(x(0), ft), lo(x(1), ft)})});
                ValueId c = inst.op == Op::Eq ? equal : op(Op::Not, Type::boolean(), {equal});
                return {c, c, true};
            }
            case Op::Splat: case Op::Compose: case Op::Extract: case Op::Shuffle: case Op::Select:
                if (t.isFloat()) return onBoth(inst, allExact);
                break;
            default: break;
        }
        // Anything else, on the values rounded to float (the high parts): a float.
        Inst copy = inst;
        for (ValueId& o : copy.operands) o = pairs_[o].hi;
        ValueId v = to_.add(copy);
        return {v, v, true};
    }

    const Kernel& from_;
    const std::vector<int>& low_;
    Kernel to_;
    std::vector<Pair> pairs_;
};

}  // namespace

bool pairedOp(Op op) {
    switch (op) {
        case Op::Add: case Op::Sub: case Op::Mul: case Op::Div: case Op::Neg: case Op::Sqrt: case Op::Pow: case Op::Dot:
            return true;
        default: return false;
    }
}

namespace {

bool writesState(const Kernel& k) {
    for (const Yield& y : k.yields)
        if (y.kind == YieldKind::StateNext) return true;
    return false;
}

}  // namespace

void doublePrecision(Module& module, PassErrors&) {
    for (Object& o : module.objects) {
        if (o.attributes.precision != Precision::Double) continue;
        // Each float slot gets its low part, starting as it does.
        std::vector<int> low(o.state.size(), -1);
        size_t slots = o.state.size();
        for (size_t s = 0; s < slots; ++s) {
            if (!o.state[s].type.isFloat()) continue;
            low[s] = static_cast<int>(o.state.size());
            o.state.push_back({o.state[s].name + "@lo", o.state[s].type, o.state[s].init});
        }
        low.resize(o.state.size(), -1);
        for (Kernel& k : o.kernels)
            if (writesState(k)) k = PairKernel(k, low).run();
    }
}

}  // namespace psys::opt
