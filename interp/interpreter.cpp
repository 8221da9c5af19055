#include "interp/interpreter.h"

#include <cmath>

#include "ir/evaluate.h"
#include "rt/rng.h"

namespace psys::interp {

using namespace ir;
using ir::Value;

void Interpreter::run(const Kernel& kernel, const rt::KernelInputs& in, std::vector<Value>& yields) {
    registers_.resize(kernel.size());
    std::vector<Value>& r = registers_;
    for (ValueId v = 0; v < kernel.size(); ++v) {
        const Inst& inst = kernel.at(v);
        const int w = inst.type.width;
        auto a = [&](size_t i) -> const Value& { return r[inst.operands[i]]; };
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
            case Op::ParentExport: out = in.parentExport(inst.attr2, inst.attr); break;
            case Op::ParentAlive: out = Value::boolean(in.parentAlive(inst.attr2)); break;
            case Op::ParentAge: out = Value::scalar(in.parentAge(inst.attr2)); break;
            case Op::ObjectId: out.u = in.objectId; break;
            case Op::DrawIndex: out.u = inst.attr == 1 ? in.childDraw : in.draw; break;
            default:
                if (isPure(inst.op)) {
                    operandValues_.clear();
                    operandTypes_.clear();
                    for (ValueId o : inst.operands) {
                        operandValues_.push_back(r[o]);
                        operandTypes_.push_back(kernel.at(o).type);
                    }
                    out = evaluate(inst, operandValues_.data(), operandTypes_.data());
                }
                break;
            case Op::Rand: case Op::NRand: {
                uint32_t object = a(0).u, draw = a(1).u, site = static_cast<uint32_t>(inst.attr);
                for (int i = 0; i < w; ++i) {
                    float u = rt::uniform01(rt::drawBits(in.seed, object, site, draw, static_cast<uint32_t>(i)));
                    out.f[static_cast<size_t>(i)] = inst.op == Op::Rand ? u : u * 2.0f - 1.0f;
                }
                break;
            }
        }
        r[v] = out;
    }
    yields.resize(kernel.yields.size());
    for (size_t i = 0; i < kernel.yields.size(); ++i) yields[i] = r[kernel.yields[i].value];
}

}  // namespace psys::interp
