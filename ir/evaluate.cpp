#include "ir/evaluate.h"

#include <stdexcept>

#include "core/hash.h"
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

// A componentwise op over the lanes, with the op known at compile time so that
// core::lane's dispatch folds away (this is the interpreter's inner loop).
template <Op op, int arity>
Value lanes(const Value* operands, size_t width) {
    Value out;
    if constexpr (arity == 1)
        for (size_t l = 0; l < width; ++l) out.f[l] = core::lane(op, operands[0].f[l]);
    else if constexpr (arity == 2)
        for (size_t l = 0; l < width; ++l) out.f[l] = core::lane(op, operands[0].f[l], operands[1].f[l]);
    return out;
}

// Every unary and binary componentwise op of core/ops.h's table, through core/lanes.h.
bool laneWise(Op op) {
    int arity = opInfo(op).arity;
    return isPure(op) && isComponentwise(op) && (arity == 1 || arity == 2);
}

Value lanesOf(Op op, const Value* operands, size_t width) {
    switch (op) {
#define PSYS_LANES(id, text, arity, kind, flags, delayed, spelling) \
    case Op::id: return lanes<Op::id, arity>(operands, width);
        PSYS_OPS(PSYS_LANES)
#undef PSYS_LANES
    }
    return {};
}

}  // namespace

Value evaluate(const Inst& inst, const Value* operands, const Type* operandTypes) {
    const auto w = static_cast<size_t>(inst.type.width);
    auto a = [&](size_t i) -> const Value& { return operands[i]; };
    Value out;
    if (laneWise(inst.op)) return lanesOf(inst.op, operands, w);
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

void Evaluator::run(const Kernel& kernel, const KernelInputs& in, std::vector<Value>& yields) {
    registers_.resize(kernel.size());
    std::vector<Value>& r = registers_;
    size_t parent = 0;
    core::HostAlgebra host;
    for (ValueId v = 0; v < kernel.size(); ++v) {
        const Inst& inst = kernel.at(v);
        Value out;
        switch (inst.op) {
            case Op::Const: out.f = inst.constant; break;
            case Op::Param: case Op::TriggerParam: out = in.params[inst.attr]; break;
            case Op::StateRead: out = in.state[inst.attr]; break;
            case Op::Extern: out = in.externs[inst.attr]; break;
            case Op::Uniform: out = in.uniforms[inst.attr]; break;
            case Op::Age: out = Value::scalar(in.age); break;
            case Op::Dt: out = Value::scalar(in.dt); break;
            case Op::Time: out = Value::scalar(in.time); break;
            case Op::First: out = Value::boolean(in.first); break;
            case Op::ParentExport: case Op::ParentAlive: case Op::ParentAge: case Op::Fold: out = in.parents[parent++]; break;
            case Op::NeighbourExport: out = (inst.attr2 ? in.other : in.self)[inst.attr]; break;
            case Op::ObjectId: out.u = in.objectId; break;
            case Op::DrawIndex: out.u = inst.attr == 1 ? in.childDraw : in.draw; break;
            case Op::Rand: case Op::NRand: {
                uint32_t object = r[inst.operands[0]].u, draw = r[inst.operands[1]].u;
                for (int i = 0; i < inst.type.width; ++i)
                    out.f[static_cast<size_t>(i)] = core::drawLane(host, inst.op, in.seed, object,
                                                                   static_cast<uint32_t>(inst.attr), draw,
                                                                   static_cast<uint32_t>(i));
                break;
            }
            default:
                if (!isPure(inst.op)) throw std::runtime_error(unexpectedOp(inst, "the interpreter"));
                operandValues_.clear();
                operandTypes_.clear();
                for (ValueId o : inst.operands) {
                    operandValues_.push_back(r[o]);
                    operandTypes_.push_back(kernel.at(o).type);
                }
                out = evaluate(inst, operandValues_.data(), operandTypes_.data());
                break;
        }
        r[v] = out;
    }
    yields.resize(kernel.yields.size());
    for (size_t i = 0; i < kernel.yields.size(); ++i) yields[i] = r[kernel.yields[i].value];
}

bool evaluates(Op op) {
    switch (op) {
        case Op::Const: case Op::Param: case Op::TriggerParam: case Op::StateRead: case Op::Extern:
        case Op::Uniform: case Op::Age: case Op::Dt: case Op::Time: case Op::First: case Op::ParentExport:
        case Op::ParentAlive: case Op::ParentAge: case Op::ObjectId: case Op::DrawIndex: case Op::Rand:
        case Op::NRand: case Op::Fold: case Op::NeighbourExport:
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
