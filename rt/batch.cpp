#include "rt/batch.h"

#include <fmt/format.h>

namespace psys::rt {

BatchLayout batchLayout(const ir::Object& object, const ir::Kernel& kernel) {
    BatchLayout l;
    int next = BatchLayout::kFirstColumn;
    auto section = [&next](std::vector<int>& offsets, auto const& items) {
        int start = next;
        for (const auto& item : items) {
            offsets.push_back(next);
            next += item.type.width;
        }
        return start;
    };
    l.state = section(l.stateOffset, object.state);
    l.params = section(l.paramOffset, object.params);
    l.exports = section(l.exportOffset, object.exports);
    l.emits = next;
    next += 2 * static_cast<int>(object.emits.size());
    l.render = next;
    next += BatchLayout::kRenderColumns;
    l.parents = next;
    for (const ir::Inst& i : kernel.insts()) {
        if (i.op != ir::Op::ParentExport && i.op != ir::Op::ParentAlive && i.op != ir::Op::ParentAge) continue;
        l.parentColumns.push_back({i.op, i.attr2, i.op == ir::Op::ParentExport ? i.attr : -1, i.type.width, next});
        next += i.type.width;
    }
    l.total = next;
    return l;
}

std::string BatchLayout::signature() const {
    std::string s = fmt::format("state {} params {} exports {} emits {} render {} parents {} total {} |", state,
                                params, exports, emits, render, parents, total);
    for (int o : stateOffset) s += fmt::format(" s{}", o);
    for (int o : paramOffset) s += fmt::format(" p{}", o);
    for (int o : exportOffset) s += fmt::format(" e{}", o);
    for (const auto& p : parentColumns) s += fmt::format(" r{}:{}:{}", p.depth, p.exportIndex, p.offset);
    return s;
}

}  // namespace psys::rt
