// split-kernels: one behaviour becomes the kernels the run-time calls (thesis §3.3.1,
// §4.3.9: split the stateful from the stateless).
//
//   init       at creation (`first` true): the starting value of every slot that starts
//              from its next value, and the size of each burst at creation (`emit … count
//              N`, and one in a `when` whose condition holds then)
//   update     every update (`first` false): every slot's next value, the kill flag, the
//              rate and count of each rate emitter, the size of each burst on an event
//              (a `when` becoming true, `on death`), and whether the step was beyond the
//              integration method's stability limit
//   render     after an update: position, colour, size, visible
//   exports    after an update: the values children read live
//   spawn.N    per object created by emit site N: its arguments
//
// The last three run after the state has been written, so they read a slot where the
// behaviour used the slot's next value; whatever they need that depended on the state
// *before* the update (a `prev`, say) is computed by update and carried in a slot of its
// own. What needs no state at all is recomputed where it is used: render can then run in
// a vertex shader.
#include <fmt/format.h>

#include <functional>

#include "ir/carried.h"
#include "opt/passes.h"
#include "opt/rewrite.h"

namespace psys::opt {

using namespace ir;

namespace {

std::vector<ValueId> rootsOf(const Kernel& k, const std::function<bool(const Yield&)>& keep) {
    std::vector<ValueId> roots;
    for (const Yield& y : k.yields)
        if (keep(y)) roots.push_back(y.value);
    return roots;
}

Kernel specialise(const Kernel& behaviour, KernelKind kind, bool first, const std::function<bool(const Yield&)>& keep) {
    Rewriter rw(behaviour);
    Kernel k = rw.run(
        [&](Rewriter& r, ValueId, const Inst& inst, const std::vector<ValueId>&) -> std::optional<ValueId> {
            if (inst.op == Op::First) return r.to().boolean(first);
            return std::nullopt;
        },
        rootsOf(behaviour, keep));
    k.kind = kind;
    std::vector<Yield> kept;
    for (const Yield& y : k.yields)
        if (keep(y)) kept.push_back(y);
    k.yields = kept;
    k.equations.clear();
    // Folding `first` left the other side of each select behind: drop what is now unused.
    Rewriter clean(k);
    Kernel out = clean.run(nullptr);
    out.kind = kind;
    return out;
}

class PostKernels {
public:
    PostKernels(Object& object, Kernel& behaviour) : object_(object), b_(behaviour) {
        for (const Yield& y : b_.yields)
            if (y.kind == YieldKind::StateNext && !cover_.count(y.value)) cover_[y.value] = y.index;
    }

    // A kernel computing the yields `keep` selects, after the state was written.
    Kernel build(KernelKind kind, int site, const std::function<bool(const Yield&)>& keep) {
        Kernel k;
        k.kind = kind;
        k.site = site;
        std::map<ValueId, ValueId> done;
        for (const Yield& y : b_.yields)
            if (keep(y)) k.yields.push_back({y.kind, y.index, y.sub, value(k, y.value, done)});
        return k;
    }

    // Values computed by update and carried to the post kernels: (slot, behaviour value).
    const std::vector<std::pair<int, ValueId>>& carried() const { return carried_; }

private:
    // Whether `v` can be computed after the update from the new state and the inputs.
    bool computable(ValueId v) {
        if (auto it = computable_.find(v); it != computable_.end()) return it->second;
        bool ok;
        if (cover_.count(v)) ok = true;
        else if (b_.at(v).op == Op::StateRead) ok = false;
        else {
            ok = true;
            for (ValueId o : b_.at(v).operands) ok &= computable(o);
        }
        return computable_[v] = ok;
    }

    ValueId value(Kernel& k, ValueId v, std::map<ValueId, ValueId>& done) {
        if (auto it = done.find(v); it != done.end()) return it->second;
        const Inst& inst = b_.at(v);
        ValueId out;
        if (auto c = cover_.find(v); c != cover_.end()) {
            out = read(k, c->second);
        } else if (!computable(v)) {
            out = read(k, carry(v));
        } else {
            Inst copy = inst;
            for (ValueId& o : copy.operands) o = value(k, o, done);
            out = k.add(std::move(copy));
        }
        return done[v] = out;
    }

    ValueId read(Kernel& k, int slot) {
        return k.add(Inst::make(Op::StateRead, object_.state[static_cast<size_t>(slot)].type, {}, slot));
    }

    int carry(ValueId v) {
        for (auto& [slot, value] : carried_)
            if (value == v) return slot;
        const Inst& inst = b_.at(v);
        object_.state.push_back({inst.name.empty() ? fmt::format("{}%{}", kCarriedSlot, v) : fmt::format("{}.{}", kCarriedSlot, inst.name), inst.type,
                                 StateInit::Next});
        int slot = static_cast<int>(object_.state.size() - 1);
        carried_.push_back({slot, v});
        cover_[v] = slot;
        return slot;
    }

    Object& object_;
    Kernel& b_;
    std::map<ValueId, int> cover_;
    std::map<ValueId, bool> computable_;
    std::vector<std::pair<int, ValueId>> carried_;
};

bool isRender(const Yield& y) { return isDrawnYield(y.kind); }

}  // namespace

void splitKernels(Module& module, PassErrors&) {
    for (Object& object : module.objects) {
        Kernel* found = object.kernel(KernelKind::Behaviour);
        if (!found) continue;
        Kernel behaviour = std::move(*found);
        std::vector<Kernel> pairs;  // the fold terms' kernels stay as they are
        for (Kernel& k : object.kernels)
            if (k.kind == KernelKind::Pair) pairs.push_back(std::move(k));
        object.kernels.clear();

        // Post-update kernels first: they decide which values update must carry.
        PostKernels post(object, behaviour);
        std::vector<Kernel> postKernels;
        postKernels.push_back(post.build(KernelKind::Render, -1, isRender));
        if (!object.exports.empty())
            postKernels.push_back(
                post.build(KernelKind::Exports, -1, [](const Yield& y) { return y.kind == YieldKind::Export; }));
        for (size_t site = 0; site < object.emits.size(); ++site)
            postKernels.push_back(post.build(KernelKind::Spawn, static_cast<int>(site), [site](const Yield& y) {
                return y.kind == YieldKind::EmitArg && y.index == static_cast<int>(site);
            }));
        for (auto& [slot, value] : post.carried()) behaviour.yields.push_back({YieldKind::StateNext, slot, 0, value});

        std::vector<bool> startsFromNext(object.state.size());
        for (size_t s = 0; s < object.state.size(); ++s) startsFromNext[s] = object.state[s].init == StateInit::Next;
        const auto& emits = object.emits;
        object.kernels.push_back(specialise(behaviour, KernelKind::Init, true, [&](const Yield& y) {
            if (y.kind == YieldKind::StateNext) return static_cast<bool>(startsFromNext[static_cast<size_t>(y.index)]);
            return y.kind == YieldKind::EmitCount && emits[static_cast<size_t>(y.index)].atCreation();
        }));
        object.kernels.push_back(specialise(behaviour, KernelKind::Update, false, [&](const Yield& y) {
            if (y.kind == YieldKind::StateNext || y.kind == YieldKind::Kill || y.kind == YieldKind::EmitRate ||
                y.kind == YieldKind::Unstable)
                return true;
            return y.kind == YieldKind::EmitCount && emits[static_cast<size_t>(y.index)].inUpdate();
        }));
        for (Kernel& k : postKernels) {
            // Rebuild to fold and order; post kernels keep `first` as an input (they also
            // run right after creation).
            Rewriter rw(k);
            Kernel clean = rw.run(nullptr);
            clean.kind = k.kind;
            clean.site = k.site;
            object.kernels.push_back(std::move(clean));
        }
        for (Kernel& k : pairs) object.kernels.push_back(std::move(k));
    }
}

}  // namespace psys::opt
