#include "ir/evaluate.h"

#include <algorithm>
#include <array>
#include <stdexcept>

#include "core/hash.h"
#include "core/instances.h"
#include "core/lanes.h"

namespace psys::ir {

namespace {

bool equal(const Value& a, const Value& b, const Type& t) {
    if (t.kind == Type::Kind::U32) return a.u == b.u;
    if (t.isBool()) return a.truth() == b.truth();
    for (int i = 0; i < t.width; ++i)
        if (a.f[static_cast<size_t>(i)] != b.f[static_cast<size_t>(i)]) return false;
    return true;
}

// A componentwise op over the lanes of n rows, with the op known at compile time so that
// core::lane's dispatch folds away (this is the interpreter's inner loop).
template <Op op, int arity>
void lanes(const Value* const* operands, size_t width, Value* out, size_t n) {
    // Lane by lane into `out` itself: a Value built on the stack and copied whole stalls
    // on store forwarding (its lanes stored one by one, then loaded as one).
    for (size_t row = 0; row < n; ++row) {
        Value& v = out[row];
        v = Value{};
        if constexpr (arity == 1)
            for (size_t l = 0; l < width; ++l) v.f[l] = core::lane(op, operands[0][row].f[l]);
        else if constexpr (arity == 2)
            for (size_t l = 0; l < width; ++l) v.f[l] = core::lane(op, operands[0][row].f[l], operands[1][row].f[l]);
    }
}

// Every unary and binary componentwise op of core/ops.h's table, through core/lanes.h.
bool laneWise(Op op) {
    int arity = opInfo(op).arity;
    return isPure(op) && isComponentwise(op) && (arity == 1 || arity == 2);
}

void lanesOf(Op op, const Value* const* operands, size_t width, Value* out, size_t n) {
    switch (op) {
#define PSYS_LANES(id, text, arity, kind, flags, delayed, spelling) \
    case Op::id: lanes<Op::id, arity>(operands, width, out, n); return;
        PSYS_OPS(PSYS_LANES)
#undef PSYS_LANES
    }
}

// Every other pure op, on one row: `operands[i][row]` is operand i's value.
Value other(const Inst& inst, const Value* const* operands, const Type* operandTypes, size_t row) {
    const auto w = static_cast<size_t>(inst.type.width);
    auto a = [&](size_t i) -> const Value& { return operands[i][row]; };
    Value out;
    switch (inst.op) {
        case Op::Lt: case Op::Le: case Op::Gt: case Op::Ge:
            return Value::boolean(core::compare(inst.op, a(0).f[0], a(1).f[0]));
        case Op::Eq: return Value::boolean(equal(a(0), a(1), operandTypes[0]));
        case Op::Ne: return Value::boolean(!equal(a(0), a(1), operandTypes[0]));
        case Op::And: return Value::boolean(a(0).truth() && a(1).truth());
        case Op::Or: return Value::boolean(a(0).truth() || a(1).truth());
        case Op::Not: return Value::boolean(!a(0).truth());
        case Op::Select: return a(0).truth() ? a(1) : a(2);
        case Op::Splat: out.f = {a(0).f[0], a(0).f[0], a(0).f[0], a(0).f[0]}; return out;
        case Op::Compose: {
            size_t n = 0;
            for (size_t i = 0; i < inst.operands.size(); ++i)
                for (int c = 0; c < operandTypes[i].width && n < 4; ++c) out.f[n++] = a(i).f[static_cast<size_t>(c)];
            return out;
        }
        case Op::Extract: return Value::scalar(a(0).f[static_cast<size_t>(inst.attr)]);
        case Op::Shuffle:
            for (size_t i = 0; i < inst.lanes.size(); ++i) out.f[i] = a(0).f[inst.lanes[i]];
            return out;
        case Op::Hash: {
            core::HostAlgebra host;
            for (size_t l = 0; l < w; ++l) out.f[l] = core::latticeLane(host, a(0).f, inst.type.width, static_cast<uint32_t>(l));
            return out;
        }
        case Op::Dot: {  // ((0 + x0·y0) + x1·y1) + …
            float s = 0;
            for (int i = 0; i < operandTypes[0].width; ++i)
                s += a(0).f[static_cast<size_t>(i)] * a(1).f[static_cast<size_t>(i)];
            return Value::scalar(s);
        }
        default: throw std::runtime_error(unexpectedOp(inst, "the interpreter"));
    }
}

// One pure instruction on n rows: `operands[i]` points at operand i's n values.
void evaluateRows(const Inst& inst, const Value* const* operands, const Type* operandTypes, Value* out, size_t n) {
    if (laneWise(inst.op)) return lanesOf(inst.op, operands, static_cast<size_t>(inst.type.width), out, n);
    for (size_t row = 0; row < n; ++row) out[row] = other(inst, operands, operandTypes, row);
}

}  // namespace

Value evaluate(const Inst& inst, const Value* operands, const Type* operandTypes) {
    // One row each: on the stack for the usual few operands (constant folding calls this
    // for every instruction it folds), a vector past them.
    std::array<const Value*, 8> few{};
    std::vector<const Value*> many;
    const Value** each = few.data();
    if (inst.operands.size() > few.size()) {
        many.resize(inst.operands.size());
        each = many.data();
    }
    for (size_t i = 0; i < inst.operands.size(); ++i) each[i] = operands + i;
    Value out;
    evaluateRows(inst, each, operandTypes, &out, 1);
    return out;
}

void Evaluator::run(const Kernel& kernel, const KernelInputs& in, std::vector<Value>& yields) {
    run(kernel, std::span<const KernelInputs>(&in, 1), yields);
}

// Instruction by instruction, each over every row: the dispatch is paid once per
// instruction and batch, not per row. Register v of row r is registers_[v * n + r].
void Evaluator::run(const Kernel& kernel, std::span<const KernelInputs> rows, std::vector<Value>& yields) {
    const size_t n = rows.size();
    if (registers_.size() < kernel.size() * n) registers_.resize(kernel.size() * n);
    Value* const r = registers_.data();
    size_t parent = 0;
    core::HostAlgebra host;
    for (ValueId v = 0; v < kernel.size(); ++v) {
        const Inst& inst = kernel.at(v);
        Value* out = r + v * n;
        auto each = [&](auto&& value) {
            for (size_t row = 0; row < n; ++row) out[row] = value(rows[row], row);
        };
        switch (inst.op) {
            case Op::Const: {
                Value c;
                c.f = inst.constant;
                std::fill(out, out + n, c);
                break;
            }
            case Op::Param: case Op::TriggerParam: each([&](const KernelInputs& in, size_t) { return in.params[inst.attr]; }); break;
            case Op::StateRead: each([&](const KernelInputs& in, size_t) { return in.state[inst.attr]; }); break;
            case Op::Extern: each([&](const KernelInputs& in, size_t) { return in.externs[inst.attr]; }); break;
            case Op::Uniform: each([&](const KernelInputs& in, size_t) { return in.uniforms[inst.attr]; }); break;
            case Op::Age: each([](const KernelInputs& in, size_t) { return Value::scalar(in.age); }); break;
            case Op::Dt: each([](const KernelInputs& in, size_t) { return Value::scalar(in.dt); }); break;
            case Op::Time: each([](const KernelInputs& in, size_t) { return Value::scalar(in.time); }); break;
            case Op::First: each([](const KernelInputs& in, size_t) { return Value::boolean(in.first); }); break;
            case Op::ParentExport: case Op::ParentAlive: case Op::ParentAge: case Op::Fold:
                each([&](const KernelInputs& in, size_t) { return in.parents[parent]; });
                ++parent;
                break;
            case Op::NeighbourExport:
                each([&](const KernelInputs& in, size_t) { return (inst.attr2 ? in.other : in.self)[inst.attr]; });
                break;
            case Op::Instance: {  // core/instances.h
                const Value* instance = r + inst.operands[0] * n;
                each([&](const KernelInputs& in, size_t row) {
                    const Value* table = in.externs + inst.attr2;
                    return table[core::instanceSlot(instance[row].f[0], static_cast<uint32_t>(table[0].f[0]), inst.attr,
                                                    core::instanceRecordValues(static_cast<size_t>(inst.attr2)))];
                });
                break;
            }
            case Op::ObjectId:
                each([](const KernelInputs& in, size_t) { Value x; x.u = in.objectId; return x; });
                break;
            case Op::DrawIndex:
                each([&](const KernelInputs& in, size_t) { Value x; x.u = inst.attr == 1 ? in.childDraw : in.draw; return x; });
                break;
            case Op::Rand: case Op::NRand: {
                const Value* object = r + inst.operands[0] * n;
                const Value* draw = r + inst.operands[1] * n;
                each([&](const KernelInputs& in, size_t row) {
                    Value x;
                    for (int i = 0; i < inst.type.width; ++i)
                        x.f[static_cast<size_t>(i)] = core::drawLane(host, inst.op, in.seed, object[row].u,
                                                                     static_cast<uint32_t>(inst.attr), draw[row].u,
                                                                     static_cast<uint32_t>(i));
                    return x;
                });
                break;
            }
            default:
                if (!isPure(inst.op)) throw std::runtime_error(unexpectedOp(inst, "the interpreter"));
                operandRows_.clear();
                operandTypes_.clear();
                for (ValueId o : inst.operands) {
                    operandRows_.push_back(r + o * n);
                    operandTypes_.push_back(kernel.at(o).type);
                }
                evaluateRows(inst, operandRows_.data(), operandTypes_.data(), out, n);
                break;
        }
    }
    yields.resize(kernel.yields.size() * n);
    for (size_t i = 0; i < kernel.yields.size(); ++i)
        std::copy_n(r + kernel.yields[i].value * n, n, yields.begin() + static_cast<std::ptrdiff_t>(i * n));
}
bool evaluates(Op op) {
    switch (op) {
        case Op::Const: case Op::Param: case Op::TriggerParam: case Op::StateRead: case Op::Extern:
        case Op::Uniform: case Op::Age: case Op::Dt: case Op::Time: case Op::First: case Op::ParentExport:
        case Op::ParentAlive: case Op::ParentAge: case Op::ObjectId: case Op::DrawIndex: case Op::Rand:
        case Op::NRand: case Op::Fold: case Op::NeighbourExport: case Op::Instance:
            return true;
        default: return isPure(op);
    }
}

std::vector<const Inst*> parentReads(const Kernel& kernel) {
    std::vector<const Inst*> reads;
    for (const Inst& i : kernel.insts())
        if (isGathered(i.op)) reads.push_back(&i);
    return reads;
}

}  // namespace psys::ir
