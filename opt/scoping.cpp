// scoping: live parent references are computed once, in the parent (thesis §4.3.5).
//
// A nested object's `rocket.pos` is lowered as `parent.read #i`. This pass makes the
// parent (or grandparent, …) export the value: an `export` yield in its behaviour, once
// per update however many children read it. The child reads `parent.export #e ^depth`
// through its parent handle, so a dead parent's last exports stay readable (frozen).
#include <fmt/format.h>

#include "opt/passes.h"

namespace psys::opt {

using namespace ir;

void scoping(Module& module, PassErrors& errors) {
    for (Object& child : module.objects) {
        if (child.parentReads.empty()) continue;
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
            Kernel* ak = ancestor.kernel(KernelKind::Behaviour);
            bool found = ak && ak->equations.count(read.member);
            if (!found) {
                errors.error(readLoc(i), fmt::format("object {}: `{}` has no equation `{}`", child.name, ancestor.name, read.member));
                resolved.push_back({0, read.depth});
                continue;
            }
            int exportIndex = -1;
            for (size_t e = 0; e < ancestor.exports.size(); ++e)
                if (ancestor.exports[e].name == read.member) exportIndex = static_cast<int>(e);
            if (exportIndex < 0) {
                exportIndex = static_cast<int>(ancestor.exports.size());
                ancestor.exports.push_back({read.member, read.type});
                ak->yields.push_back({YieldKind::Export, exportIndex, 0, ak->equations.at(read.member)});
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
}

}  // namespace psys::opt
