#include "opt/pattern.h"

#include <cstring>

#include "ir/evaluate.h"

namespace psys::opt {

using namespace ir;

namespace {

Pat node(Op op, std::vector<Pat> operands) {
    Pat p;
    p.kind = Pat::Kind::Op;
    p.op = op;
    p.operands = std::move(operands);
    return p;
}

bool bind(Bindings& b, int slot, ValueId v) {
    auto s = static_cast<size_t>(slot);
    if (b.bound[s]) return b.value[s] == v;
    b.bound[s] = true;
    b.value[s] = v;
    return true;
}

bool matchValue(const Kernel& k, const Pat& p, ValueId v, Bindings& b);

// The operands of an instruction against a pattern's, in order or (commutative) swapped.
bool matchOperands(const Kernel& k, const Pat& p, const Inst& inst, Bindings& b) {
    if (p.op != inst.op || p.operands.size() != inst.operands.size()) return false;
    Bindings saved = b;
    bool ok = true;
    for (size_t i = 0; i < p.operands.size() && ok; ++i) ok = matchValue(k, p.operands[i], inst.operands[i], b);
    if (ok) return true;
    b = saved;
    if (!isCommutative(inst.op) || inst.operands.size() != 2) return false;
    ok = matchValue(k, p.operands[0], inst.operands[1], b) && matchValue(k, p.operands[1], inst.operands[0], b);
    if (!ok) b = saved;
    return ok;
}

bool matchValue(const Kernel& k, const Pat& p, ValueId v, Bindings& b) {
    const Inst& inst = k.at(v);
    switch (p.kind) {
        case Pat::Kind::Var: return bind(b, p.var, v);
        case Pat::Kind::AnyConst: return inst.op == Op::Const && bind(b, p.var, v);
        case Pat::Kind::Literal: return constantAll(k, v, p.literal);
        case Pat::Kind::Op: return matchOperands(k, p, inst, b);
    }
    return false;
}

bool yieldsBool(Op op) {
    switch (op) {
        case Op::Lt: case Op::Le: case Op::Gt: case Op::Ge: case Op::Eq: case Op::Ne:
        case Op::And: case Op::Or: case Op::Not:
            return true;
        default:
            return false;
    }
}

ValueId build(Rewriter& rw, const Pat& p, const Bindings& b, Type type) {
    Kernel& k = rw.to();
    switch (p.kind) {
        case Pat::Kind::Var: case Pat::Kind::AnyConst: return b[p.var];
        case Pat::Kind::Literal: {
            float x = p.literal;
            return k.constant(type, {x, x, x, x});
        }
        case Pat::Kind::Op: break;
    }
    // Operands: values first, then literals of the values' type.
    std::vector<ValueId> operands(p.operands.size(), 0);
    std::optional<Type> valueType;
    for (size_t i = 0; i < p.operands.size(); ++i) {
        if (p.operands[i].kind == Pat::Kind::Literal) continue;
        operands[i] = build(rw, p.operands[i], b, type);
        if (!valueType && k.at(operands[i]).type.isFloat()) valueType = k.at(operands[i]).type;
    }
    for (size_t i = 0; i < p.operands.size(); ++i)
        if (p.operands[i].kind == Pat::Kind::Literal) operands[i] = build(rw, p.operands[i], b, valueType.value_or(type));
    Type t = yieldsBool(p.op) ? Type::boolean() : type;
    bool allConstant = isPure(p.op);
    for (ValueId o : operands) allConstant &= k.at(o).op == Op::Const;
    Inst inst = Inst::make(p.op, t, operands);
    if (allConstant) {
        std::vector<Value> values;
        std::vector<Type> types;
        for (ValueId o : operands) {
            values.push_back({k.at(o).constant, 0});
            types.push_back(k.at(o).type);
        }
        return k.constant(t, evaluate(inst, values.data(), types.data()).f);
    }
    return rw.emit(std::move(inst));
}

}  // namespace

Pat var(int slot) { return {Pat::Kind::Var, slot, 0, Op::Const, {}}; }
Pat constant(int slot) { return {Pat::Kind::AnyConst, slot, 0, Op::Const, {}}; }
Pat lit(float value) { return {Pat::Kind::Literal, 0, value, Op::Const, {}}; }
Pat operator+(Pat a, Pat b) { return node(Op::Add, {std::move(a), std::move(b)}); }
Pat operator-(Pat a, Pat b) { return node(Op::Sub, {std::move(a), std::move(b)}); }
Pat operator*(Pat a, Pat b) { return node(Op::Mul, {std::move(a), std::move(b)}); }
Pat operator/(Pat a, Pat b) { return node(Op::Div, {std::move(a), std::move(b)}); }
Pat operator-(Pat a) { return node(Op::Neg, {std::move(a)}); }
Pat operator!(Pat a) { return node(Op::Not, {std::move(a)}); }
Pat min(Pat a, Pat b) { return node(Op::Min, {std::move(a), std::move(b)}); }
Pat max(Pat a, Pat b) { return node(Op::Max, {std::move(a), std::move(b)}); }
Pat both(Pat a, Pat b) { return node(Op::And, {std::move(a), std::move(b)}); }
Pat either(Pat a, Pat b) { return node(Op::Or, {std::move(a), std::move(b)}); }
Pat select(Pat c, Pat a, Pat b) { return node(Op::Select, {std::move(c), std::move(a), std::move(b)}); }
Pat splat(Pat a) { return node(Op::Splat, {std::move(a)}); }
Pat extract(Pat a) { return node(Op::Extract, {std::move(a)}); }
Pat shuffle(Pat a) { return node(Op::Shuffle, {std::move(a)}); }

Rule rewrite(std::string name, Pat from, Pat to, Condition when, bool relaxedOnly) {
    return {std::move(name), std::move(from), std::move(to), std::move(when), relaxedOnly};
}

bool constantAll(const Kernel& k, ValueId v, float x) {
    const Inst& i = k.at(v);
    if (i.op != Op::Const || !i.type.isFloat()) return false;
    for (int c = 0; c < i.type.width; ++c)
        if (std::memcmp(&i.constant[static_cast<size_t>(c)], &x, sizeof x) != 0) return false;
    return true;
}

std::optional<ValueId> Rules::tryRule(Rewriter& rw, const Rule& r, const Inst& inst) const {
    Bindings b;
    if (r.from.kind != Pat::Kind::Op || !matchOperands(rw.to(), r.from, inst, b)) return std::nullopt;
    if (r.when && !r.when(rw.to(), b)) return std::nullopt;
    return build(rw, r.to, b, inst.type);
}

std::optional<ValueId> Rules::apply(Rewriter& rw, const Inst& inst, bool relaxed, const std::string** fired) const {
    for (auto [declarative, index] : order_) {
        std::optional<ValueId> v;
        const std::string* name;
        if (declarative) {
            const Rule& r = rules_[index];
            if (r.relaxedOnly && !relaxed) continue;
            v = tryRule(rw, r, inst);
            name = &r.name;
        } else {
            const ProceduralPattern& p = patterns_[index];
            if ((p.relaxedOnly && !relaxed) || (p.root != Op::Const && p.root != inst.op)) continue;
            v = p.apply(rw, inst);
            name = &p.name;
        }
        if (v) {
            if (fired) *fired = name;
            return v;
        }
    }
    return std::nullopt;
}

}  // namespace psys::opt
