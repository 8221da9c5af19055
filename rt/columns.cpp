#include "rt/columns.h"

#include <stdexcept>

#include <fmt/format.h>

namespace psys::rt {

ColumnLayout columnLayout(const ir::Object& object, const ir::Kernel& kernel) {
    ColumnLayout l;
    int next = ColumnLayout::kFirstColumn;
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
    l.renderColumns = ir::renderColumns(object);
    next += l.renderColumns;
    l.parents = next;
    l.writes.assign(static_cast<size_t>(l.parents - l.emits), false);
    l.emitShared.assign(static_cast<size_t>(l.render - l.emits), {});
    // The rest is the compiler's record (ir::KernelStorage, opt/lower_storage.cpp).
    const ir::KernelStorage& st = kernel.storage;
    if (!st.fixed)
        throw std::logic_error(fmt::format("internal error: the {} kernel of `{}` has no storage record (the module "
                                           "was not compiled: opt's lower-storage)", ir::kernelName(kernel.kind),
                                           object.name));
    for (const ir::Yield& y : kernel.yields)
        if (y.kind == ir::YieldKind::EmitRate || y.kind == ir::YieldKind::EmitCount)
            l.writes[static_cast<size_t>((y.kind == ir::YieldKind::EmitRate ? l.emitRate(y.index) : l.emitCount(y.index)) - l.emits)] = true;
    using From = ColumnLayout::Shared::From;
    for (size_t c = 0; c < st.emits.size() && c < l.emitShared.size(); ++c) {
        const ir::KernelStorage::Shared& e = st.emits[c];
        switch (e.from) {
            case ir::KernelStorage::Shared::From::Column: break;
            case ir::KernelStorage::Shared::From::Constant: l.emitShared[c] = {From::Constant, 0, e.value}; break;
            case ir::KernelStorage::Shared::From::Extern: l.emitShared[c] = {From::Extern, e.index, 0}; break;
            case ir::KernelStorage::Shared::From::Uniform: l.emitShared[c] = {From::Uniform, e.index, 0}; break;
        }
    }
    if (kernel.kind == ir::KernelKind::Render) {  // writes every render column (visible: drawn or not)…
        const auto columns = static_cast<size_t>(l.renderColumns);
        l.renderFromState.assign(columns, -1);  // …but those drawn from state or constants
        l.renderConstant.assign(columns, {});
        for (size_t c = 0; c < st.drawn.size() && c < columns; ++c) {
            const ir::KernelStorage::Drawn& d = st.drawn[c];
            if (d.from == ir::KernelStorage::Drawn::From::State)
                l.renderFromState[c] = l.stateOffset.at(static_cast<size_t>(d.slot)) + d.lane;
            if (d.from == ir::KernelStorage::Drawn::From::Constant) l.renderConstant[c] = {true, d.value};
        }
        for (int c = 0; c < l.renderColumns; ++c)
            l.writes[static_cast<size_t>(l.render - l.emits + c)] =
                l.renderFromState[static_cast<size_t>(c)] < 0 && !l.renderConstant[static_cast<size_t>(c)].is;
    }
    for (const ir::KernelStorage::ParentRead& p : st.parents) {
        l.parentColumns.push_back({p.op, p.depth, p.exportIndex, p.width, next});
        next += p.width;
    }
    l.total = next;
    return l;
}

ArgumentColumns argumentColumns(const ir::Kernel& spawn) {
    ArgumentColumns a;
    argumentColumns(spawn, a);
    return a;
}

void argumentColumns(const ir::Kernel& spawn, ArgumentColumns& a) {
    a.first.clear();
    a.total = 0;
    for (const ir::Yield& y : spawn.yields)
        if (y.kind == ir::YieldKind::EmitArg) {
            auto sub = static_cast<size_t>(y.sub);
            if (a.first.size() <= sub) a.first.resize(sub + 1, 0);
            a.first[sub] = static_cast<size_t>(spawn.at(y.value).type.width);  // its width, for now
        }
    for (size_t& c : a.first) {
        size_t width = c;
        c = a.total;
        a.total += width;
    }
}

int ColumnLayout::renderColumn(ir::YieldKind kind, int index) { return ir::drawnColumn(kind, index); }
static_assert(ColumnLayout::kVisible == ir::drawnColumn(ir::YieldKind::Visible) &&
              ColumnLayout::kPosition == ir::drawnColumn(ir::YieldKind::Position) &&
              ColumnLayout::kColor == ir::drawnColumn(ir::YieldKind::Color) &&
              ColumnLayout::kSize == ir::drawnColumn(ir::YieldKind::Size) &&
              ColumnLayout::kRenderColumns == ir::kDrawnColumns &&
              ColumnLayout::kTrail == ir::drawnColumn(ir::YieldKind::Trail, 0));

std::string ColumnLayout::signature() const {
    std::string s = fmt::format("state {} params {} exports {} emits {} render {} parents {} total {} |", state,
                                params, exports, emits, render, parents, total);
    for (int o : stateOffset) s += fmt::format(" s{}", o);
    for (int o : paramOffset) s += fmt::format(" p{}", o);
    for (int o : exportOffset) s += fmt::format(" e{}", o);
    for (const auto& p : parentColumns) s += fmt::format(" r{}:{}:{}", p.depth, p.exportIndex, p.offset);
    for (int c : renderFromState) s += fmt::format(" d{}", c);
    for (size_t c = 0; c < renderConstant.size(); ++c)
        if (renderConstant[c].is) s += fmt::format(" k{}={:a}", c, renderConstant[c].value);
    return s;
}

const ir::Kernel* initKernel(const ir::Object& object) {
    const ir::Kernel* init = object.kernel(ir::KernelKind::Init);
    return init && !init->yields.empty() ? init : nullptr;
}

}  // namespace psys::rt
