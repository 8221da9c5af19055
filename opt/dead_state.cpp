// dead-state: keep only the state, and the parameters, a scene needs.
//
// After the split, every kernel reads slots by index. This pass
//   - removes a slot nothing needs: one read by no kernel, or read only to compute its own
//     next value or the next value of other slots nothing needs (a `derive` whose result
//     is never used, say);
//   - merges slots that always hold the same value: the same type, the same start and the
//     same next value (bouncing's velocity was stored twice: once to close the cycle,
//     once for an explicit `prev`) — not in a system that may be reloaded;
//   - stops storing a slot whose next value is the slot itself (it never changes after
//     creation);
//   - marks a parameter no kernel after `init` reads as not kept: it is used at creation
//     and the pool does not store it — but in a system that may be reloaded, which
//     carries parameters by name (PassOptions::reloadable).
#include <set>

#include <fmt/format.h>

#include "opt/passes.h"
#include "opt/rewrite.h"

namespace psys::opt {

using namespace ir;

namespace {

// The slots (and parameters) `roots` read, through operands.
void reads(const Kernel& k, std::vector<ValueId> roots, std::set<int>& slots, std::set<int>* params = nullptr) {
    std::vector<bool> seen(k.size(), false);
    while (!roots.empty()) {
        ValueId v = roots.back();
        roots.pop_back();
        if (seen[v]) continue;
        seen[v] = true;
        const Inst& i = k.at(v);
        if (i.op == Op::StateRead) slots.insert(i.attr);
        if (i.op == Op::Param && params) params->insert(i.attr);
        for (ValueId o : i.operands) roots.push_back(o);
    }
}

// Rewrites slot indices: `map[old]` is the new index, or -1 for a removed slot.
void renumber(Object& o, const std::vector<int>& map) {
    for (Kernel& k : o.kernels) {
        std::vector<Yield> kept;
        for (Yield y : k.yields) {
            if (y.kind == YieldKind::StateNext) {
                if (map[static_cast<size_t>(y.index)] < 0) continue;
                y.index = map[static_cast<size_t>(y.index)];
            }
            kept.push_back(y);
        }
        k.yields = kept;
        for (ValueId v = 0; v < k.size(); ++v) {
            Inst& i = k.mutableAt(v);
            if (i.op == Op::StateRead) i.attr = std::max(0, map[static_cast<size_t>(i.attr)]);
        }
        k.rehash();
        Rewriter rw(k);
        Kernel clean = rw.run(nullptr);
        clean.kind = k.kind;
        clean.site = k.site;
        k = std::move(clean);
    }
    std::vector<StateSlot> state;
    for (size_t s = 0; s < o.state.size(); ++s)
        if (map[s] >= 0) {
            if (state.size() < static_cast<size_t>(map[s]) + 1) state.resize(static_cast<size_t>(map[s]) + 1);
            state[static_cast<size_t>(map[s])] = o.state[s];
        }
    o.state = state;
}

void eliminate(Object& o, bool reloadable) {
    const bool keepEach = reloadable, keepParams = reloadable;
    Kernel* update = o.kernel(KernelKind::Update);
    Kernel* init = o.kernel(KernelKind::Init);
    if (!update) return;
    size_t n = o.state.size();
    auto nextIn = [&](const Kernel* k, size_t slot) -> std::optional<ValueId> {
        if (!k) return std::nullopt;
        if (const Yield* y = k->findOne(YieldKind::StateNext, static_cast<int>(slot))) return y->value;
        return std::nullopt;
    };

    // Merge slots with the same type, start and next value into the first of them — but
    // in a system that may be reloaded, which carries each slot by its name (and relaxed
    // maths' rewrites can make slots equal that exact maths keeps apart).
    std::vector<int> map(n);
    for (size_t s = 0; s < n; ++s) map[s] = static_cast<int>(s);
    for (size_t b = 0; b < n && !keepEach; ++b)
        for (size_t a = 0; a < b; ++a) {
            if (map[a] != static_cast<int>(a)) continue;
            bool same = o.state[a].type == o.state[b].type && o.state[a].init == o.state[b].init &&
                        nextIn(update, a) && nextIn(update, a) == nextIn(update, b) && nextIn(init, a) == nextIn(init, b);
            if (same) {
                map[b] = static_cast<int>(a);
                break;
            }
        }
    bool merged = false;
    for (size_t s = 0; s < n; ++s) merged |= map[s] != static_cast<int>(s);
    if (merged) {
        // Reads of a merged slot read the one it merged into; its own yields go.
        for (Kernel& k : o.kernels) {
            std::vector<Yield> kept;
            for (const Yield& y : k.yields)
                if (y.kind != YieldKind::StateNext || map[static_cast<size_t>(y.index)] == y.index) kept.push_back(y);
            k.yields = kept;
            for (ValueId v = 0; v < k.size(); ++v) {
                Inst& i = k.mutableAt(v);
                if (i.op == Op::StateRead) i.attr = map[static_cast<size_t>(i.attr)];
            }
            k.rehash();
        }
    }

    // Live slots: read by a post-update kernel, or for a kill flag, an emission, an
    // export, or the next value of a live slot.
    std::set<int> live;
    for (const Kernel& k : o.kernels) {
        if (k.kind == KernelKind::Update || k.kind == KernelKind::Init) {
            std::vector<ValueId> roots;
            for (const Yield& y : k.yields)
                if (y.kind != YieldKind::StateNext) roots.push_back(y.value);
            reads(k, roots, live);
        } else {
            std::vector<ValueId> roots;
            for (const Yield& y : k.yields) roots.push_back(y.value);
            reads(k, roots, live);
        }
    }
    for (size_t round = 0; round <= n; ++round) {
        size_t before = live.size();
        for (int s : std::set<int>(live))
            if (auto v = nextIn(update, static_cast<size_t>(s))) reads(*update, {*v}, live);
        if (live.size() == before) break;
    }
    std::vector<int> renumbered(n, -1);
    int next = 0;
    for (size_t s = 0; s < n; ++s)
        if (map[s] == static_cast<int>(s) && live.count(static_cast<int>(s))) renumbered[s] = next++;
    renumber(o, renumbered);

    // A slot whose next value is itself is never stored by update.
    update = o.kernel(KernelKind::Update);
    std::vector<Yield> kept;
    for (const Yield& y : update->yields) {
        bool unchanged = y.kind == YieldKind::StateNext && update->at(y.value).op == Op::StateRead &&
                         update->at(y.value).attr == y.index;
        if (!unchanged) kept.push_back(y);
    }
    update->yields = kept;
    Rewriter rw(*update);
    Kernel clean = rw.run(nullptr);
    clean.kind = KernelKind::Update;
    *update = std::move(clean);

    // Parameters: kept only if a kernel after creation reads them — or the host does (an
    // event's values: ir::eventType).
    std::set<int> slotsUnused, params;
    for (const Kernel& k : o.kernels) {
        if (k.kind == KernelKind::Init) continue;
        std::vector<ValueId> roots;
        for (const Yield& y : k.yields) roots.push_back(y.value);
        reads(k, roots, slotsUnused, &params);
    }
    const bool hostReads = isEventType(o.name);
    for (size_t p = 0; p < o.params.size(); ++p)
        o.params[p].kept = keepParams || hostReads || params.count(static_cast<int>(p)) > 0;
}

}  // namespace

void deadState(Module& module, const PassOptions& options, PassErrors&) {
    for (Object& o : module.objects) eliminate(o, options.reloadable);
}

}  // namespace psys::opt
