#include "opt/linear_part.h"

#include <set>

namespace psys::opt {

using namespace ir;

namespace {

class LinearPart {
public:
    LinearPart(const Kernel& k, ValueId integral, bool throughPrev)
        : k_(k), integral_(integral), throughPrev_(throughPrev) {}

    std::optional<Coefficient> of(ValueId v) {
        if (v == integral_) return Coefficient{Coefficient::Kind::One, k_.at(v).type, 0, {}};
        if (!depends(v)) return std::nullopt;
        const Inst& i = k_.at(v);
        auto op = [&](size_t n) { return i.operands[n]; };
        auto combine = [&](Coefficient::Kind kind, std::vector<Coefficient> parts, ValueId factor = 0) {
            return Coefficient{kind, i.type, factor, std::move(parts)};
        };
        switch (i.op) {
            case Op::Recur: return of(op(0));
            case Op::Prev:
                if (throughPrev_) return of(op(0));
                return std::nullopt;
            case Op::Neg:
                if (auto a = of(op(0))) return combine(Coefficient::Kind::Neg, {*a});
                return std::nullopt;
            case Op::Add: case Op::Sub: {
                auto a = of(op(0)), b = of(op(1));
                if (a && b) return combine(i.op == Op::Add ? Coefficient::Kind::Add : Coefficient::Kind::Sub, {*a, *b});
                if (a) return a;
                if (b && i.op == Op::Sub) return combine(Coefficient::Kind::Neg, {*b});
                return b;
            }
            case Op::Mul:
                for (size_t n = 0; n < 2; ++n)
                    if (!depends(op(1 - n)))
                        if (auto a = of(op(n))) return combine(Coefficient::Kind::Mul, {*a}, op(1 - n));
                return std::nullopt;
            case Op::Div:
                if (!depends(op(1)))
                    if (auto a = of(op(0))) return combine(Coefficient::Kind::Div, {*a}, op(1));
                return std::nullopt;
            default: return std::nullopt;  // not linear: part of the rest
        }
    }

private:
    // Whether `v` reads the integral (within this update: other integrals are leaves).
    bool depends(ValueId v) {
        if (auto it = depends_.find(v); it != depends_.end()) return it->second;
        std::vector<ValueId> work = {v};
        std::set<ValueId> seen;
        bool found = false;
        while (!work.empty() && !found) {
            ValueId x = work.back();
            work.pop_back();
            if (!seen.insert(x).second) continue;
            if (x == integral_) found = true;
            const Inst& i = k_.at(x);
            if (i.op == Op::Integrate || (i.op == Op::Prev && !throughPrev_)) continue;
            for (ValueId o : i.operands) work.push_back(o);
        }
        return depends_[v] = found;
    }

    const Kernel& k_;
    ValueId integral_;
    bool throughPrev_;
    std::map<ValueId, bool> depends_;
};

}  // namespace

std::optional<Coefficient> linearPart(const Kernel& k, ValueId derivative, ValueId integral, bool throughPrev) {
    return LinearPart(k, integral, throughPrev).of(derivative);
}

ValueId build(const Coefficient& c, Kernel& to, const std::function<ValueId(ValueId)>& leaf) {
    auto part = [&](size_t n) { return build(c.parts[n], to, leaf); };
    auto is = [&](size_t n, Coefficient::Kind kind) { return c.parts.size() > n && c.parts[n].kind == kind; };
    switch (c.kind) {
        case Coefficient::Kind::One: return to.constant(c.type, {1, 1, 1, 1});
        case Coefficient::Kind::Neg:
            if (is(0, Coefficient::Kind::Neg)) return build(c.parts[0].parts[0], to, leaf);  // −(−x) = x exactly
            return to.op(Op::Neg, c.type, {part(0)});
        case Coefficient::Kind::Add: return to.op(Op::Add, c.type, {part(0), part(1)});
        case Coefficient::Kind::Sub: return to.op(Op::Sub, c.type, {part(0), part(1)});
        case Coefficient::Kind::Mul:
            if (is(0, Coefficient::Kind::One)) return leaf(c.factor);  // x·1 = x exactly
            return to.op(Op::Mul, c.type, {leaf(c.factor), part(0)});
        case Coefficient::Kind::Div: return to.op(Op::Div, c.type, {part(0), leaf(c.factor)});
    }
    return 0;
}

std::optional<std::array<double, 4>> constantValue(const Coefficient& c, const Kernel& k) {
    using V = std::array<double, 4>;
    auto lanes = [&](std::optional<V> v) {  // the lanes past the type's width are 0
        if (v)
            for (size_t l = c.type.width; l < 4; ++l) (*v)[l] = 0;
        return v;
    };
    auto zip = [](V a, V b, auto f) {
        for (size_t l = 0; l < 4; ++l) a[l] = f(a[l], b[l]);
        return a;
    };
    std::vector<V> parts;
    for (const Coefficient& p : c.parts) {
        auto v = constantValue(p, k);
        if (!v) return std::nullopt;
        parts.push_back(*v);
    }
    V factor{};
    if (c.kind == Coefficient::Kind::Mul || c.kind == Coefficient::Kind::Div) {
        // A constant, or a constant spread over a vector (before simplify folds it).
        const Inst* f = &k.at(c.factor);
        bool spread = f->op == Op::Splat;
        if (spread) f = &k.at(f->operands[0]);
        if (f->op != Op::Const) return std::nullopt;
        for (size_t l = 0; l < 4; ++l) factor[l] = f->constant[spread ? 0 : l];
    }
    switch (c.kind) {
        case Coefficient::Kind::One: return lanes(V{1, 1, 1, 1});
        case Coefficient::Kind::Neg: return lanes(zip(parts[0], parts[0], [](double a, double) { return -a; }));
        case Coefficient::Kind::Add: return lanes(zip(parts[0], parts[1], [](double a, double b) { return a + b; }));
        case Coefficient::Kind::Sub: return lanes(zip(parts[0], parts[1], [](double a, double b) { return a - b; }));
        case Coefficient::Kind::Mul: return lanes(zip(factor, parts[0], [](double a, double b) { return a * b; }));
        case Coefficient::Kind::Div: return lanes(zip(parts[0], factor, [](double a, double b) { return a / b; }));
    }
    return std::nullopt;
}

}  // namespace psys::opt
