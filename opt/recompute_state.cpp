// recompute-state (relaxed maths only): a slot the next step can compute again is not stored.
//
// The fire's `vel = … + integrate(acc)` keeps last step's `acc` as state (the integral's
// previous integrand): 12 bytes read and 12 written a particle a step, where `acc` is
// `gravity − vel + push(temp(age))`, a function of values the next step reads anyway (the
// stored `vel`) and of the clock. Memory is what a particle update waits for; a few
// arithmetic operations are not. So when a slot's next value is, through pure operations,
// a function of only
//   - the next values of other stored slots (the next step reads them back as they are),
//   - `age` and `time` (one step later: `age − dt`, `time − dt`),
//   - constants,
// every read of the slot is replaced by that function of the stored slots, and dead-state
// then drops the slot. The recomputed value starts where the stored one did only if the
// slot's start (its `init` value) is the same function of the other slots' starts at age
// 0, which is checked. `age − dt` is the previous step's age up to rounding, so the result
// may differ in the last bits: relaxed maths only. So nothing is recomputed through an
// operation whose result can jump where its operands move by their last bits (a
// comparison, floor, step …: core/ops.h's kJumps): `when age > 1.04`'s last value,
// recomputed from `age − dt`, is true a step early wherever the previous age was 1.04 to
// the last bit (ages on a 1/100 s grid, steps of 1/30 s), and the edge never fires. Not
// recomputed either: anything reading `dt`
// (the previous step's is not known), externs and parents (they may have changed),
// random draws, parameters (the pool may not keep them: recomputing must never cost
// bytes), and functions of more than kMaxOps operations.
#include <functional>
#include <map>
#include <set>

#include "opt/passes.h"
#include "opt/rewrite.h"

namespace psys::opt {

using namespace ir;

namespace {

constexpr size_t kMaxOps = 32;

// The value each slot's next value is in a kernel (update or init): one slot per value.
std::map<ValueId, int> nextValues(const Kernel& k) {
    std::map<ValueId, int> out;
    for (const Yield& y : k.yields)
        if (y.kind == YieldKind::StateNext) out.emplace(y.value, y.index);
    return out;
}

// Whether `root` (slot `slot`'s next value in `update`) can be computed from the other
// slots' next values (`cut`), the clock and constants within kMaxOps operations.
bool recomputable(const Kernel& update, ValueId root, int slot, const std::map<ValueId, int>& cut) {
    std::set<ValueId> seen;
    std::function<bool(ValueId, bool)> walk = [&](ValueId v, bool isRoot) {
        if (!isRoot) {
            auto c = cut.find(v);
            if (c != cut.end()) return c->second != slot;
        }
        if (!seen.insert(v).second) return true;
        if (seen.size() > kMaxOps) return false;
        const Inst& i = update.at(v);
        if (i.op == Op::Const || i.op == Op::Age || i.op == Op::Time) return true;
        if (!isPure(i.op) || jumps(i.op)) return false;
        for (ValueId o : i.operands)
            if (!walk(o, false)) return false;
        return true;
    };
    return walk(root, true);
}

// Whether `u` in `update` and `i` in `init` compute the same function, the other slots'
// next values standing for the same slot's start value.
bool sameFunction(const Kernel& update, ValueId u, const std::map<ValueId, int>& updateCut, const Kernel& init,
                  ValueId i, const std::map<ValueId, int>& initCut, bool isRoot) {
    if (!isRoot) {
        auto a = updateCut.find(u), b = initCut.find(i);
        if (a != updateCut.end() || b != initCut.end())
            return a != updateCut.end() && b != initCut.end() && a->second == b->second;
    }
    const Inst& x = update.at(u);
    const Inst& y = init.at(i);
    if (x.op != y.op || x.type != y.type || x.attr != y.attr || x.attr2 != y.attr2 || x.constant != y.constant ||
        x.lanes != y.lanes || x.operands.size() != y.operands.size())
        return false;
    for (size_t k = 0; k < x.operands.size(); ++k)
        if (!sameFunction(update, x.operands[k], updateCut, init, y.operands[k], initCut, false)) return false;
    return true;
}

// Copies `root` of `update` into the kernel `r` builds: the other slots' next values become
// reads of those slots; in the update kernel itself (`earlier`) the clock is one step back.
ValueId rebuild(Rewriter& r, const Kernel& update, ValueId root, const std::map<ValueId, int>& cut, bool earlier) {
    std::map<ValueId, ValueId> done;
    std::function<ValueId(ValueId, bool)> copy = [&](ValueId v, bool isRoot) -> ValueId {
        if (auto d = done.find(v); d != done.end()) return d->second;
        const Inst& i = update.at(v);
        ValueId out;
        if (auto c = cut.find(v); !isRoot && c != cut.end()) {
            out = r.emit(Inst::make(Op::StateRead, i.type, {}, c->second));
        } else if (earlier && (i.op == Op::Age || i.op == Op::Time)) {
            ValueId clock = r.emit(i);
            Inst dt = Inst::make(Op::Dt, i.type);
            dt.loc = i.loc;
            Inst back = Inst::make(Op::Sub, i.type, {clock, r.emit(dt)});
            back.loc = i.loc;
            out = r.emit(back);
        } else {
            Inst copied = i;
            for (ValueId& o : copied.operands) o = copy(o, false);
            out = r.emit(copied);
        }
        done.emplace(v, out);
        return out;
    };
    return copy(root, true);
}

// Replaces every read of `slot` in the object's kernels; returns whether it did.
bool recomputeSlot(Object& o, int slot) {
    Kernel* update = o.kernel(KernelKind::Update);
    Kernel* init = o.kernel(KernelKind::Init);
    if (!update || !init || o.state[static_cast<size_t>(slot)].init != StateInit::Next) return false;
    const Yield* next = update->findOne(YieldKind::StateNext, slot);
    const Yield* start = init->findOne(YieldKind::StateNext, slot);
    if (!next || !start) return false;
    std::map<ValueId, int> cut = nextValues(*update), initCut = nextValues(*init);
    // Another slot with the same next value is dead-state's to merge.
    cut.erase(next->value);
    for (auto& [v, s] : cut)
        if (s == slot) return false;
    initCut.erase(start->value);
    if (!recomputable(*update, next->value, slot, cut)) return false;
    if (!sameFunction(*update, next->value, cut, *init, start->value, initCut, true)) return false;

    const Kernel source = *update;
    const ValueId root = next->value;
    for (Kernel& k : o.kernels) {
        if (k.kind == KernelKind::Init) continue;
        const bool earlier = k.kind == KernelKind::Update;
        Rewriter rw(k);
        Kernel rebuilt = rw.run([&](Rewriter& r, ValueId, const Inst& inst, const std::vector<ValueId>&) -> std::optional<ValueId> {
            if (inst.op != Op::StateRead || inst.attr != slot) return std::nullopt;
            return rebuild(r, source, root, cut, earlier);
        });
        rebuilt.kind = k.kind;
        rebuilt.site = k.site;
        k = std::move(rebuilt);
    }
    // Nothing reads the slot now: it is neither started nor stored (dead-state drops it).
    for (Kernel* k : {o.kernel(KernelKind::Update), o.kernel(KernelKind::Init)})
        std::erase_if(k->yields, [&](const Yield& y) { return y.kind == YieldKind::StateNext && y.index == slot; });
    return true;
}

void recomputeObject(Object& o) {
    // One slot at a time: a recomputed slot's function reads the slots still stored.
    for (size_t round = 0; round < o.state.size(); ++round) {
        bool changed = false;
        for (size_t s = 0; s < o.state.size() && !changed; ++s) {
            const Kernel* update = o.kernel(KernelKind::Update);
            bool read = false;
            for (const Kernel& k : o.kernels)
                for (const Inst& i : k.insts()) read |= k.kind != KernelKind::Init && i.op == Op::StateRead && i.attr == static_cast<int>(s);
            if (!update || !read) continue;
            changed = recomputeSlot(o, static_cast<int>(s));
        }
        if (!changed) break;
    }
}

}  // namespace

void recomputeState(Module& module, PassErrors&) {
    for (Object& o : module.objects) recomputeObject(o);
}

}  // namespace psys::opt
