#include "ir/verifier.h"

#include "core/instances.h"

#include <fmt/format.h>

namespace psys::ir {
namespace {

class Verifier {
public:
    Verifier(const Module& m, std::vector<std::string>& errors) : module_(m), errors_(errors) {}

    void kernel(const Kernel& k, const Object* object, const Trigger* trigger, const std::string& where) {
        where_ = where + ", kernel " + kernelName(k.kind);
        kernel_ = &k;
        object_ = object;
        trigger_ = trigger;
        bool behaviour = k.kind == KernelKind::Behaviour;
        // Trigger and start kernels are written like behaviours: their draws are keyed later.
        unkeyedDrawsAllowed_ = behaviour || k.kind == KernelKind::Trigger || k.kind == KernelKind::Start;
        if (k.kind == KernelKind::Pair && (!object || k.site < 0 || static_cast<size_t>(k.site) >= object->neighbours.size()))
            fail(fmt::format("a pair kernel of group #{}, which the object does not have", k.site));
        for (ValueId v = 0; v < k.size(); ++v) inst(k, v, behaviour);
        for (const Yield& y : k.yields) yield(k, y);
        if (k.storage.fixed) storage(k);
    }

private:
    // A storage record (lower-storage) that still fits its kernel: a pass after it that
    // changed the instructions would leave it stale.
    void storage(const Kernel& k) {
        const KernelStorage& st = k.storage;
        if (object_ && st.emits.size() != 2 * object_->emits.size())
            fail(fmt::format("storage: {} emit columns for {} emit sites", st.emits.size(), object_->emits.size()));
        if (object_ && st.drawn.size() > static_cast<size_t>(renderColumns(*object_)))
            fail(fmt::format("storage: {} render columns for an object that has {}", st.drawn.size(),
                             renderColumns(*object_)));
        for (size_t c = 0; c < st.drawn.size(); ++c) {
            const KernelStorage::Drawn& d = st.drawn[c];
            if (d.from != KernelStorage::Drawn::From::State) continue;
            bool ok = object_ && d.slot >= 0 && static_cast<size_t>(d.slot) < object_->state.size() && d.lane >= 0 &&
                      d.lane < object_->state[static_cast<size_t>(d.slot)].type.width;
            if (!ok) fail(fmt::format("storage: {} drawn from a state lane that does not exist", drawnColumnName(static_cast<int>(c))));
        }
        size_t reads = 0;
        for (const Inst& i : k.insts()) {
            if (!isGathered(i.op)) continue;
            const KernelStorage::ParentRead* p = reads < st.parents.size() ? &st.parents[reads] : nullptr;
            if (!p || p->op != i.op || p->depth != i.attr2 || p->width != i.type.width ||
                p->exportIndex != (i.op == Op::ParentExport || i.op == Op::Fold ? i.attr : -1))
                fail(fmt::format("storage: parent read {} is not the kernel's", reads));
            ++reads;
        }
        if (reads != st.parents.size()) fail(fmt::format("storage: {} parent reads for {}", st.parents.size(), reads));
        for (int slot : st.zeroed)
            if (!object_ || slot < 0 || static_cast<size_t>(slot) >= object_->state.size())
                fail(fmt::format("storage: zeroed slot #{} does not exist", slot));
    }

    void fail(ValueId v, const std::string& what) { errors_.push_back(fmt::format("{}, %{}: {}", where_, v, what)); }
    void fail(const std::string& what) { errors_.push_back(fmt::format("{}: {}", where_, what)); }

    void inst(const Kernel& k, ValueId v, bool behaviour) {
        const Inst& i = k.at(v);
        const OpInfo& info = opInfo(i.op);
        bool keyedRandom = (i.op == Op::Rand || i.op == Op::NRand) && (i.operands.size() == 2 || unkeyedDrawsAllowed_);
        if ((isTemporal(i.op) || (isRandom(i.op) && !keyedRandom)) && !behaviour) fail(v, fmt::format("`{}` outside a behaviour kernel", info.name));
        if (info.arity >= 0 && static_cast<int>(i.operands.size()) != info.arity)
            return fail(v, fmt::format("`{}` takes {} operands, has {}", info.name, info.arity, i.operands.size()));
        for (size_t n = 0; n < i.operands.size(); ++n) {
            ValueId o = i.operands[n];
            if (o >= k.size()) return fail(v, fmt::format("operand %{} does not exist", o));
            if (o >= v && !(behaviour && mayReferForward(i.op, n)))
                return fail(v, fmt::format("operand %{} is not defined before its use", o));
        }
        auto t = [&](size_t n) { return k.at(i.operands[n]).type; };
        auto expect = [&](bool ok, const char* what) {
            if (!ok) fail(v, fmt::format("`{}.{}`: {}", info.name, i.type.str(), what));
        };
        switch (i.op) {
            case Op::Const: break;
            case Op::Param: {
                const std::vector<Param>* params = object_ ? &object_->params : trigger_ ? &trigger_->params : nullptr;
                expect(params && i.attr >= 0 && static_cast<size_t>(i.attr) < params->size() &&
                           (*params)[static_cast<size_t>(i.attr)].type == i.type,
                       "no parameter of this index and type");
                break;
            }
            case Op::TriggerParam:
                expect(trigger_ && i.attr >= 0 && static_cast<size_t>(i.attr) < trigger_->params.size() &&
                           trigger_->params[static_cast<size_t>(i.attr)].type == i.type,
                       "no trigger parameter of this index and type");
                break;
            case Op::StateRead:
                expect(object_ && i.attr >= 0 && static_cast<size_t>(i.attr) < object_->state.size() &&
                           object_->state[static_cast<size_t>(i.attr)].type == i.type,
                       "no state slot of this index and type");
                break;
            case Op::Extern:
                expect(i.attr >= 0 && static_cast<size_t>(i.attr) < module_.externs.size() &&
                           module_.externs[static_cast<size_t>(i.attr)].type == i.type,
                       "no extern of this index and type");
                break;
            case Op::ParentRead:
                expect(object_ && i.attr >= 0 && static_cast<size_t>(i.attr) < object_->parentReads.size() &&
                           object_->parentReads[static_cast<size_t>(i.attr)].type == i.type,
                       "no parent read of this index and type");
                break;
            case Op::ParentExport: {
                const Object* ancestor = object_;
                for (int d = 0; ancestor && d < i.attr2; ++d) ancestor = module_.object(ancestor->parent);
                expect(i.attr2 >= 1 && ancestor && i.attr >= 0 && static_cast<size_t>(i.attr) < ancestor->exports.size() &&
                           ancestor->exports[static_cast<size_t>(i.attr)].type == i.type,
                       "no export of this index and type in that ancestor");
                break;
            }
            case Op::NeighbourRead:
                expect(kernel_->kind == KernelKind::Pair && object_ && i.attr >= 0 &&
                           static_cast<size_t>(i.attr) < object_->neighbourReads.size() &&
                           object_->neighbourReads[static_cast<size_t>(i.attr)].type == i.type,
                       "no neighbour read of this index and type in a pair kernel");
                break;
            case Op::NeighbourExport: {
                const NeighbourGroup* g = object_ && kernel_->site >= 0 &&
                                                  static_cast<size_t>(kernel_->site) < object_->neighbours.size()
                                              ? &object_->neighbours[static_cast<size_t>(kernel_->site)]
                                              : nullptr;
                const Object* from = !g ? nullptr : i.attr2 == 1 ? module_.object(g->target) : object_;
                expect(kernel_->kind == KernelKind::Pair && (i.attr2 == 0 || i.attr2 == 1) && from && i.attr >= 0 &&
                           static_cast<size_t>(i.attr) < from->exports.size() &&
                           from->exports[static_cast<size_t>(i.attr)].type == i.type,
                       "no export of this index and type in this object (^0) or the other (^1) of a pair kernel");
                break;
            }
            case Op::Fold:
                expect(kernel_->kind != KernelKind::Pair && object_ && i.attr >= 0 &&
                           static_cast<size_t>(i.attr) < object_->folds.size() &&
                           object_->folds[static_cast<size_t>(i.attr)].type == i.type,
                       "no fold of this index and type (outside a pair kernel)");
                break;
            case Op::Instance:
                expect(t(0).isScalarFloat() && i.attr >= 0 && static_cast<size_t>(i.attr2) == module_.externs.size() &&
                           (i.attr < core::kInstanceOwnValues
                                ? i.type == Type::vec(4)
                                : static_cast<uint32_t>(i.attr) < core::instanceRecordValues(module_.externs.size()) &&
                                      i.type == module_.externs[static_cast<size_t>(i.attr - core::kInstanceOwnValues)].type),
                       "value #k of the record of the instance an f32 names, the table after the externs (^count): a "
                       "vec4 for #0…#3, extern #k−4's type past them");
                break;
            case Op::ParentAlive: expect(i.type.isBool() && i.attr2 >= 1, "a bool, at least one level up"); break;
            case Op::ParentAge: expect(i.type.isScalarFloat() && i.attr2 >= 1, "an f32, at least one level up"); break;
            case Op::Age: case Op::Dt: case Op::Time: expect(i.type.isScalarFloat(), "an f32"); break;
            case Op::First: expect(i.type.isBool(), "a bool"); break;
            case Op::ObjectId: case Op::DrawIndex: expect(i.type == Type::u32(), "a u32"); break;
            case Op::Uniform: {
                auto served = uniformFor(kernel_->kind);
                const Kernel* u = object_ && served ? object_->kernel(*served) : nullptr;
                const Yield* y = u ? u->findOne(YieldKind::Uniform, i.attr) : nullptr;
                expect(y && u->at(y->value).type == i.type, "no uniform value of this index and type");
                break;
            }
            case Op::Lt: case Op::Le: case Op::Gt: case Op::Ge:
                expect(i.type.isBool() && t(0).isScalarFloat() && t(1).isScalarFloat(), "compares two f32 to a bool");
                break;
            case Op::Eq: case Op::Ne: expect(i.type.isBool() && t(0) == t(1), "compares equal types to a bool"); break;
            case Op::And: case Op::Or: expect(i.type.isBool() && t(0).isBool() && t(1).isBool(), "on bools"); break;
            case Op::Not: expect(i.type.isBool() && t(0).isBool(), "on a bool"); break;
            case Op::Select: expect(t(0).isBool() && t(1) == i.type && t(2) == i.type, "select(bool, T, T) -> T"); break;
            case Op::Splat: expect(i.type.isVector() && t(0).isScalarFloat(), "an f32 to a vector"); break;
            case Op::Compose: {
                int width = 0;
                bool floats = true;
                for (size_t n = 0; n < i.operands.size(); ++n) {
                    width += t(n).width;
                    floats &= t(n).isFloat();
                }
                expect(i.type.isVector() && floats && width == i.type.width, "components adding up to the vector");
                break;
            }
            case Op::Extract:
                expect(i.type.isScalarFloat() && t(0).isVector() && i.attr >= 0 && i.attr < t(0).width,
                       "a component of a vector");
                break;
            case Op::Shuffle: {
                bool ok = t(0).isVector() && i.type.isFloat() && i.type.width == static_cast<int>(i.lanes.size());
                for (uint8_t l : i.lanes) ok &= l < t(0).width;
                expect(ok, "lanes of a vector");
                break;
            }
            case Op::Hash: expect(i.type.isFloat() && t(0) == i.type, "floats, as many as its operand's"); break;
            case Op::Dot: expect(i.type.isScalarFloat() && t(0) == t(1) && t(0).isFloat(), "f32 of two equal vectors"); break;
            case Op::Rand: case Op::NRand:
                // No operands (a draw key-random has not keyed yet), or exactly the key's two.
                expect(i.type.isFloat() &&
                           (i.operands.empty() || (i.operands.size() == 2 && t(0) == Type::u32() && t(1) == Type::u32())),
                       "floats, keyed by two u32 (object id, draw)");
                break;
            case Op::Integrate: case Op::Derive: expect(i.type.isFloat() && t(0) == i.type, "T -> T on floats"); break;
            case Op::Snapshot: case Op::Prev: case Op::Recur: expect(t(0) == i.type, "T -> T"); break;
            case Op::FollowedBy: expect(t(0) == i.type && t(1) == i.type, "(T, T) -> T"); break;
            default:  // componentwise arithmetic and maths
                expect(i.type.isFloat(), "on floats");
                for (size_t n = 0; n < i.operands.size(); ++n) expect(t(n) == i.type, "operands of the result's type");
                break;
        }
    }

    void yield(const Kernel& k, const Yield& y) {
        if (y.value >= k.size()) return fail(fmt::format("yield of %{}, which does not exist", y.value));
        Type t = k.at(y.value).type;
        auto expect = [&](bool ok, const std::string& what) {
            if (!ok) fail(fmt::format("yield {} #{} = %{}: {}", static_cast<int>(y.kind), y.index, y.value, what));
        };
        const std::vector<EmitSite>* emits = object_ ? &object_->emits : trigger_ ? &trigger_->emits : nullptr;
        switch (y.kind) {
            case YieldKind::StateNext:
                expect(object_ && y.index >= 0 && static_cast<size_t>(y.index) < object_->state.size() &&
                           object_->state[static_cast<size_t>(y.index)].type == t,
                       "no state slot of this index and type");
                break;
            case YieldKind::Kill: case YieldKind::Visible: case YieldKind::Unstable: expect(t.isBool(), "a bool"); break;
            case YieldKind::Position: case YieldKind::End: expect(t == Type::vec(3), "a vec3"); break;
            case YieldKind::Trail:
                expect(t == Type::vec(3), "a vec3");
                expect(object_ && y.index >= 0 && y.index < object_->trail - 1, "no such point of the object's trail");
                break;
            case YieldKind::Rotation: case YieldKind::Frame: expect(t.isScalarFloat(), "an f32"); break;
            case YieldKind::Color: expect(t == Type::vec(4), "a vec4"); break;
            case YieldKind::Size: case YieldKind::EmitRate: case YieldKind::EmitCount:
                expect(t.isScalarFloat(), "an f32");
                if (y.kind != YieldKind::Size)
                    expect(emits && y.index >= 0 && static_cast<size_t>(y.index) < emits->size(), "no such emit site");
                break;
            case YieldKind::EmitArg: {
                bool ok = emits && y.index >= 0 && static_cast<size_t>(y.index) < emits->size();
                const Object* target = ok ? module_.object((*emits)[static_cast<size_t>(y.index)].target) : nullptr;
                expect(target && y.sub >= 0 && static_cast<size_t>(y.sub) < target->params.size() &&
                           target->params[static_cast<size_t>(y.sub)].type == t,
                       "not an argument of the emitted object");
                break;
            }
            case YieldKind::Uniform: expect(y.index >= 0, "a uniform index"); break;
            case YieldKind::Fold:
                expect(k.kind == KernelKind::Pair && object_ && y.index >= 0 &&
                           static_cast<size_t>(y.index) < object_->folds.size() &&
                           object_->folds[static_cast<size_t>(y.index)].type == t &&
                           object_->folds[static_cast<size_t>(y.index)].group == k.site,
                       "no fold of this index, type and group");
                break;
            case YieldKind::Export:
                expect(object_ && y.index >= 0 && static_cast<size_t>(y.index) < object_->exports.size() &&
                           object_->exports[static_cast<size_t>(y.index)].type == t,
                       "no export of this index and type");
                break;
        }
    }

    const Module& module_;
    std::vector<std::string>& errors_;
    std::string where_;
    const Object* object_ = nullptr;
    const Trigger* trigger_ = nullptr;
    bool unkeyedDrawsAllowed_ = false;
    const Kernel* kernel_ = nullptr;
};

}  // namespace

std::vector<std::string> verify(const Module& module) {
    std::vector<std::string> errors;
    Verifier v(module, errors);
    for (const Object& o : module.objects) {
        if (!o.parent.empty() && !module.object(o.parent))
            errors.push_back(fmt::format("object {}: its parent `{}` does not exist", o.name, o.parent));
        for (const EmitSite& e : o.emits)
            if (!module.object(e.target)) errors.push_back(fmt::format("object {}: emits unknown `{}`", o.name, e.target));
        for (const NeighbourGroup& g : o.neighbours)
            if (!module.object(g.target) || !(g.radius > 0))
                errors.push_back(fmt::format("object {}: folds over unknown `{}` or within a radius not above 0", o.name,
                                             g.target));
        for (const Fold& f : o.folds)
            if (f.group < 0 || static_cast<size_t>(f.group) >= o.neighbours.size())
                errors.push_back(fmt::format("object {}: a fold of a group that does not exist", o.name));
        for (const Kernel& k : o.kernels) v.kernel(k, &o, nullptr, "object " + o.name);
    }
    for (const Trigger& t : module.triggers) v.kernel(t.kernel, nullptr, &t, "trigger " + t.name);
    v.kernel(module.start.kernel, nullptr, &module.start, "start");
    return errors;
}

}  // namespace psys::ir
