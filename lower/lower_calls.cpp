// Lowering calls: user functions are inlined (each inlined `rand` is a call site of its
// own), and the library's functions become arithmetic the passes can see through.
#include "core/lanes.h"
#include "frontend/builtins.h"
#include "lower/object_lowering.h"

namespace psys::lower::detail {

Values ObjectLowering::lowerCall(const CallExpr& c) {
    if (c.neighbours) return {lowerNear(c)};
    if (c.fn) {
        FnFrame frame{c.fn, {}, {}};
        for (auto& a : c.args) frame.params.push_back(lower(*a));
        frames_.push_back(std::move(frame));
        for (auto& let : c.fn->lets) {
            Values v = lower(*let->value);
            frames_.back().lets[let.get()] = v;
        }
        Values result = lower(*c.fn->body);
        frames_.pop_back();
        return result;
    }
    const BuiltinFunction& fn = builtinFunction(c.builtin);
    Type t = irType(c.type);
    // State of a tuple (`prev((p, q))`, `snapshot(two(age))`) is one slot per element.
    if (fn.rule == BuiltinRule::Prev) {
        Values prevs;
        for (const psys::Type& element : c.type.isTuple() ? c.type.elements() : std::vector<psys::Type>{c.type})
            prevs.push_back(temporal(Op::Prev, irType(element), {0}));
        deferred_.push_back({prevs, c.args[0].get(), frames_});
        return prevs;
    }
    if (fn.rule == BuiltinRule::Snapshot) {
        Values out;
        for (ValueId v : lower(*c.args[0])) out.push_back(temporal(Op::Snapshot, k_.at(v).type, {v}));
        return out;
    }
    std::vector<ValueId> a;
    for (auto& arg : c.args) a.push_back(lowerOne(*arg));
    auto b = [&](size_t i) { return broadcastTo(a.at(i), t); };
    auto unary = [&](Op op) { return Values{k_.op(op, t, {b(0)})}; };
    auto binary = [&](Op op) { return Values{k_.op(op, t, {b(0), b(1)})}; };
    auto mix = [&](ValueId x, ValueId y, ValueId s) {  // x + (y - x) * s
        return k_.op(Op::Add, t, {x, k_.op(Op::Mul, t, {k_.op(Op::Sub, t, {y, x}), s})});
    };
    auto clamp = [&](ValueId x, ValueId lo, ValueId hi) {
        return k_.op(Op::Min, t, {k_.op(Op::Max, t, {x, lo}), hi});
    };
    std::string_view n = fn.name;
    switch (fn.rule) {
        case BuiltinRule::Componentwise:
            if (fn.op) return opInfo(*fn.op).arity == 1 ? unary(*fn.op) : binary(*fn.op);
            if (n == "radians") return {k_.op(Op::Mul, t, {b(0), scalarConst(core::kRadiansPerDegree, t)})};
            if (n == "degrees") return {k_.op(Op::Mul, t, {b(0), scalarConst(core::kDegreesPerRadian, t)})};
            if (n == "saturate") return {clamp(b(0), scalarConst(0, t), scalarConst(1, t))};
            if (n == "clamp")
                return {clamp(b(0), a.size() > 1 ? b(1) : scalarConst(0, t), a.size() > 2 ? b(2) : scalarConst(1, t))};
            if (n == "mix" || n == "lerp") return {mix(b(0), b(1), b(2))};
            if (n == "smoothstep") {  // s = clamp((x - e0) / (e1 - e0)); s * s * (3 - 2 * s)
                ValueId s = clamp(k_.op(Op::Div, t, {k_.op(Op::Sub, t, {b(2), b(0)}), k_.op(Op::Sub, t, {b(1), b(0)})}),
                                  scalarConst(0, t), scalarConst(1, t));
                ValueId poly = k_.op(Op::Sub, t, {scalarConst(3, t), k_.op(Op::Mul, t, {scalarConst(2, t), s})});
                return {k_.op(Op::Mul, t, {k_.op(Op::Mul, t, {s, s}), poly})};
            }
            break;
        case BuiltinRule::ToScalar: {
            if (n == "dot") return {k_.op(Op::Dot, Type::f32(), {a[0], a[1]})};
            ValueId v = n == "distance" ? k_.op(Op::Sub, k_.at(a[0]).type, {a[0], a[1]}) : a[0];
            if (!k_.at(v).type.isVector()) return {k_.op(Op::Abs, Type::f32(), {v})};
            return {k_.op(Op::Sqrt, Type::f32(), {k_.op(Op::Dot, Type::f32(), {v, v})})};
        }
        case BuiltinRule::SameVector: {
            if (n == "normalize") {  // v * (1 / sqrt(dot(v, v)))
                ValueId inv = k_.op(Op::Div, Type::f32(),
                                    {k_.scalar(1), k_.op(Op::Sqrt, Type::f32(), {k_.op(Op::Dot, Type::f32(), {a[0], a[0]})})});
                return {k_.op(Op::Mul, t, {a[0], broadcastTo(inv, t)})};
            }
            // reflect(v, n) = v - 2 * dot(n, v) * n
            ValueId d = k_.op(Op::Mul, Type::f32(), {k_.scalar(2), k_.op(Op::Dot, Type::f32(), {a[1], a[0]})});
            return {k_.op(Op::Sub, t, {a[0], k_.op(Op::Mul, t, {broadcastTo(d, t), a[1]})})};
        }
        case BuiltinRule::Cross: {  // a.yzx * b.zxy - a.zxy * b.yzx
            ValueId l = k_.op(Op::Mul, t, {shuffle(a[0], {1, 2, 0}), shuffle(a[1], {2, 0, 1})});
            ValueId r = k_.op(Op::Mul, t, {shuffle(a[0], {2, 0, 1}), shuffle(a[1], {1, 2, 0})});
            return {k_.op(Op::Sub, t, {l, r})};
        }
        case BuiltinRule::Rotate: {
            ValueId c = k_.op(Op::Cos, Type::f32(), {a[1]}), s = k_.op(Op::Sin, Type::f32(), {a[1]});
            ValueId x = extract(a[0], 0), y = extract(a[0], 1), z = extract(a[0], 2);
            auto f = [&](Op op, ValueId p, ValueId q) { return k_.op(op, Type::f32(), {p, q}); };
            auto rot = [&](ValueId u, ValueId w) {  // (u cos - w sin, u sin + w cos)
                return std::pair{f(Op::Sub, f(Op::Mul, u, c), f(Op::Mul, w, s)),
                                 f(Op::Add, f(Op::Mul, u, s), f(Op::Mul, w, c))};
            };
            if (n == "rotate_x") {
                auto [ny, nz] = rot(y, z);
                return {k_.op(Op::Compose, t, {x, ny, nz})};
            }
            if (n == "rotate_y") {  // right-handed about +y: z towards x
                auto [nz, nx] = rot(z, x);
                return {k_.op(Op::Compose, t, {nx, y, nz})};
            }
            auto [nx, ny] = rot(x, y);
            return {k_.op(Op::Compose, t, {nx, ny, z})};
        }
        case BuiltinRule::Construct:
            if (a.size() == 1 && k_.at(a[0]).type.width == 1) return {k_.op(Op::Splat, t, {a[0]})};
            return {k_.op(Op::Compose, t, a)};
        case BuiltinRule::Integrate:
            return {temporal(n == "integrate" ? Op::Integrate : Op::Derive, t, {a[0]})};
        case BuiltinRule::Snapshot:
        case BuiltinRule::Prev:
        case BuiltinRule::Neighbours: break;  // handled above
        case BuiltinRule::Random:
            return {temporal(n.substr(0, 1) == "n" ? Op::NRand : Op::Rand, t, {})};
    }
    return {k_.scalar(0)};
}


}  // namespace psys::lower::detail
