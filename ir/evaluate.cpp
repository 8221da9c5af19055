#include "ir/evaluate.h"

#include <cmath>

namespace psys::ir {

namespace {

template <typename F>
Value map1(const Value& a, int width, F f) {
    Value r;
    for (int i = 0; i < width; ++i) r.f[static_cast<size_t>(i)] = f(a.f[static_cast<size_t>(i)]);
    return r;
}

template <typename F>
Value map2(const Value& a, const Value& b, int width, F f) {
    Value r;
    for (int i = 0; i < width; ++i) r.f[static_cast<size_t>(i)] = f(a.f[static_cast<size_t>(i)], b.f[static_cast<size_t>(i)]);
    return r;
}

bool equal(const Value& a, const Value& b, const Type& t) {
    if (t.kind == Type::Kind::U32) return a.u == b.u;
    if (t.isBool()) return a.truth() == b.truth();
    for (int i = 0; i < t.width; ++i)
        if (a.f[static_cast<size_t>(i)] != b.f[static_cast<size_t>(i)]) return false;
    return true;
}

}  // namespace

bool isPure(Op op) { return op >= Op::Add && op <= Op::Dot; }

Value evaluate(const Inst& inst, const Value* operands, const Type* operandTypes) {
    const int w = inst.type.width;
    auto a = [&](size_t i) -> const Value& { return operands[i]; };
    Value out;
    switch (inst.op) {
        case Op::Add: out = map2(a(0), a(1), w, [](float x, float y) { return x + y; }); break;
        case Op::Sub: out = map2(a(0), a(1), w, [](float x, float y) { return x - y; }); break;
        case Op::Mul: out = map2(a(0), a(1), w, [](float x, float y) { return x * y; }); break;
        case Op::Div: out = map2(a(0), a(1), w, [](float x, float y) { return x / y; }); break;
        case Op::Mod: out = map2(a(0), a(1), w, [](float x, float y) { return x - y * std::floor(x / y); }); break;
        case Op::Neg: out = map1(a(0), w, [](float x) { return -x; }); break;
        case Op::Min: out = map2(a(0), a(1), w, [](float x, float y) { return y < x ? y : x; }); break;
        case Op::Max: out = map2(a(0), a(1), w, [](float x, float y) { return x < y ? y : x; }); break;
        case Op::Step: out = map2(a(0), a(1), w, [](float edge, float x) { return x < edge ? 0.0f : 1.0f; }); break;
        case Op::Atan2: out = map2(a(0), a(1), w, [](float y, float x) { return std::atan2(y, x); }); break;
        case Op::Pow: out = map2(a(0), a(1), w, [](float x, float y) { return std::pow(x, y); }); break;
        case Op::Sin: out = map1(a(0), w, [](float x) { return std::sin(x); }); break;
        case Op::Cos: out = map1(a(0), w, [](float x) { return std::cos(x); }); break;
        case Op::Tan: out = map1(a(0), w, [](float x) { return std::tan(x); }); break;
        case Op::Asin: out = map1(a(0), w, [](float x) { return std::asin(x); }); break;
        case Op::Acos: out = map1(a(0), w, [](float x) { return std::acos(x); }); break;
        case Op::Atan: out = map1(a(0), w, [](float x) { return std::atan(x); }); break;
        case Op::Exp: out = map1(a(0), w, [](float x) { return std::exp(x); }); break;
        case Op::Log: out = map1(a(0), w, [](float x) { return std::log(x); }); break;
        case Op::Sqrt: out = map1(a(0), w, [](float x) { return std::sqrt(x); }); break;
        case Op::Abs: out = map1(a(0), w, [](float x) { return std::fabs(x); }); break;
        case Op::Sign: out = map1(a(0), w, [](float x) { return x > 0 ? 1.0f : x < 0 ? -1.0f : 0.0f; }); break;
        case Op::Floor: out = map1(a(0), w, [](float x) { return std::floor(x); }); break;
        case Op::Ceil: out = map1(a(0), w, [](float x) { return std::ceil(x); }); break;
        case Op::Round: out = map1(a(0), w, [](float x) { return std::nearbyint(x); }); break;
        case Op::Fract: out = map1(a(0), w, [](float x) { return x - std::floor(x); }); break;
        case Op::Lt: out = Value::boolean(a(0).f[0] < a(1).f[0]); break;
        case Op::Le: out = Value::boolean(a(0).f[0] <= a(1).f[0]); break;
        case Op::Gt: out = Value::boolean(a(0).f[0] > a(1).f[0]); break;
        case Op::Ge: out = Value::boolean(a(0).f[0] >= a(1).f[0]); break;
        case Op::Eq: out = Value::boolean(equal(a(0), a(1), operandTypes[0])); break;
        case Op::Ne: out = Value::boolean(!equal(a(0), a(1), operandTypes[0])); break;
        case Op::And: out = Value::boolean(a(0).truth() && a(1).truth()); break;
        case Op::Or: out = Value::boolean(a(0).truth() || a(1).truth()); break;
        case Op::Not: out = Value::boolean(!a(0).truth()); break;
        case Op::Select: out = a(0).truth() ? a(1) : a(2); break;
        case Op::Splat: out.f = {a(0).f[0], a(0).f[0], a(0).f[0], a(0).f[0]}; break;
        case Op::Compose: {
            size_t n = 0;
            for (size_t i = 0; i < inst.operands.size(); ++i) {
                int cw = operandTypes[i].width;
                for (int c = 0; c < cw && n < 4; ++c) out.f[n++] = a(i).f[static_cast<size_t>(c)];
            }
            break;
        }
        case Op::Extract: out = Value::scalar(a(0).f[static_cast<size_t>(inst.attr)]); break;
        case Op::Shuffle:
            for (size_t i = 0; i < inst.lanes.size(); ++i) out.f[i] = a(0).f[inst.lanes[i]];
            break;
        case Op::Dot: {
            float s = 0;
            for (int i = 0; i < operandTypes[0].width; ++i)
                s += a(0).f[static_cast<size_t>(i)] * a(1).f[static_cast<size_t>(i)];
            out = Value::scalar(s);
            break;
        }
        default: break;
    }
    return out;
}

}  // namespace psys::ir
