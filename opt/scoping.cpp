// scoping: live references to other objects are computed once, in the object read
// (thesis §4.3.5).
//
// A nested object's `rocket.pos` is lowered as `parent.read #i`. This pass makes the
// parent (or grandparent, …) export the value: an `export` yield in its behaviour, once
// per update however many children read it. The child reads `parent.export #e ^depth`
// through its parent handle, so a dead parent's last exports stay readable (frozen).
//
// A neighbour fold's term reads both objects of a pair the same way: `neighbour.read #i`
// becomes `neighbour.export #e ^0` (this object's export e) or `^1` (the other's), and
// each group's two drawn positions — what the fold measures distances between — are
// exports too.
#include <fmt/format.h>

#include "opt/passes.h"

namespace psys::opt {

using namespace ir;

namespace {

constexpr const char* kPositionExport = "(position)";

// The export of `object` holding its equation `member` (made if there is none, unless
// another export holds the same value); -1 if the object has no such equation.
int exportOf(Object& object, const std::string& member, Type type) {
    for (size_t e = 0; e < object.exports.size(); ++e)
        if (object.exports[e].name == member) return static_cast<int>(e);
    Kernel* k = object.kernel(KernelKind::Behaviour);
    ValueId value = 0;
    if (member == kPositionExport) {
        const Yield* p = k ? k->findOne(YieldKind::Position) : nullptr;
        if (!p) return -1;
        value = p->value;
    } else {
        if (!k || !k->equations.count(member)) return -1;
        value = k->equations.at(member);
    }
    // One value, one export (a position that is an equation: `point(pos, …)`).
    for (const Yield& y : k->yields)
        if (y.kind == YieldKind::Export && y.value == value && object.exports.at(static_cast<size_t>(y.index)).type == type)
            return y.index;
    int index = static_cast<int>(object.exports.size());
    object.exports.push_back({member, type});
    k->yields.push_back({YieldKind::Export, index, 0, value});
    return index;
}

void scopeParents(Module& module, Object& child, PassErrors& errors) {
    Kernel* k = child.kernel(KernelKind::Behaviour);
    std::vector<std::pair<int, int>> resolved;  // per read: (export index, depth)
    // Where read `i` is written (its first parent.read instruction).
    auto readLoc = [&](size_t i) {
        for (const Inst& inst : k->insts())
            if (inst.op == Op::ParentRead && inst.attr == static_cast<int>(i)) return inst.loc;
        return child.loc;
    };
    for (size_t i = 0; i < child.parentReads.size(); ++i) {
        const ParentRead& read = child.parentReads[i];
        int ancestorIndex = module.objectIndex(child.parent);
        for (int d = 1; d < read.depth && ancestorIndex >= 0; ++d)
            ancestorIndex = module.objectIndex(module.objects[static_cast<size_t>(ancestorIndex)].parent);
        if (ancestorIndex < 0) {
            errors.error(readLoc(i), fmt::format("object {}: no ancestor {} levels up", child.name, read.depth));
            resolved.push_back({0, read.depth});
            continue;
        }
        Object& ancestor = module.objects[static_cast<size_t>(ancestorIndex)];
        int exportIndex = exportOf(ancestor, read.member, read.type);
        if (exportIndex < 0) {
            errors.error(readLoc(i), fmt::format("object {}: `{}` has no equation `{}`", child.name, ancestor.name, read.member));
            exportIndex = 0;
        }
        resolved.push_back({exportIndex, read.depth});
    }
    for (ValueId v = 0; v < k->size(); ++v) {
        Inst& inst = k->mutableAt(v);
        if (inst.op != Op::ParentRead) continue;
        auto [exportIndex, depth] = resolved.at(static_cast<size_t>(inst.attr));
        inst.op = Op::ParentExport;
        inst.attr = exportIndex;
        inst.attr2 = depth;
    }
    k->rehash();
    child.parentReads.clear();
}

void scopeNeighbours(Module& module, size_t self, PassErrors& errors) {
    for (Kernel& pair : module.objects[self].kernels) {
        if (pair.kind != KernelKind::Pair) continue;
        Object& object = module.objects[self];
        NeighbourGroup& g = object.neighbours.at(static_cast<size_t>(pair.site));
        int targetIndex = module.objectIndex(g.target);
        Loc at = pair.size() ? pair.at(0).loc : object.loc;
        if (targetIndex < 0) {
            errors.error(at, fmt::format("object {}: folds over unknown `{}`", object.name, g.target));
            continue;
        }
        Object& target = module.objects[static_cast<size_t>(targetIndex)];
        Object& me = module.objects[self];
        g.selfPosition = exportOf(me, kPositionExport, Type::vec(3));
        g.otherPosition = exportOf(target, kPositionExport, Type::vec(3));
        auto drawsNothing = [&](const Object& o) {
            errors.error(at, fmt::format("object {}: a fold over `{}` measures between drawn positions, but `{}` "
                                         "draws nothing (give it a `point`, `sprite`, `streak` or `trail`)",
                                         me.name, target.name, o.name));
        };
        if (g.selfPosition < 0) drawsNothing(me);
        if (g.otherPosition < 0 && &target != &me) drawsNothing(target);  // a fold over its own type: said once
        for (ValueId v = 0; v < pair.size(); ++v) {
            Inst& inst = pair.mutableAt(v);
            if (inst.op != Op::NeighbourRead) continue;
            const NeighbourRead& read = me.neighbourReads.at(static_cast<size_t>(inst.attr));
            Object& from = read.other ? target : me;
            int e = exportOf(from, read.member, read.type);
            if (e < 0) {
                errors.error(inst.loc, fmt::format("object {}: `{}` has no equation `{}`", me.name, from.name, read.member));
                e = 0;
            }
            inst.op = Op::NeighbourExport;
            inst.attr = e;
            inst.attr2 = read.other ? 1 : 0;
        }
        pair.rehash();
    }
    module.objects[self].neighbourReads.clear();
}

}  // namespace

void scoping(Module& module, PassErrors& errors) {
    for (Object& child : module.objects)
        if (!child.parentReads.empty()) scopeParents(module, child, errors);
    for (size_t i = 0; i < module.objects.size(); ++i)
        if (!module.objects[i].neighbours.empty()) scopeNeighbours(module, i, errors);
}

}  // namespace psys::opt
