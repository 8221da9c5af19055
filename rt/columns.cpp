#include "rt/columns.h"

#include <fmt/format.h>

namespace psys::rt {

namespace {

// Lane `lane` of `v` when it is a constant: a constant, a splat of one, or a lane of a
// compose that is.
std::optional<float> constantLane(const ir::Kernel& k, ir::ValueId v, int lane) {
    const ir::Inst& i = k.at(v);
    switch (i.op) {
        case ir::Op::Const: return i.type.isBool() ? std::nullopt : std::optional<float>(i.constant[static_cast<size_t>(lane)]);
        case ir::Op::Splat: return constantLane(k, i.operands[0], 0);
        case ir::Op::Compose:
            for (ir::ValueId o : i.operands) {
                int width = k.at(o).type.width;
                if (lane < width) return constantLane(k, o, lane);
                lane -= width;
            }
            return std::nullopt;
        default: return std::nullopt;
    }
}

}  // namespace

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
    next += ColumnLayout::kRenderColumns;
    l.parents = next;
    l.writes.assign(static_cast<size_t>(l.parents - l.emits), false);
    l.emitShared.assign(static_cast<size_t>(l.render - l.emits), {});
    for (const ir::Yield& y : kernel.yields) {
        if (y.kind != ir::YieldKind::EmitRate && y.kind != ir::YieldKind::EmitCount) continue;
        auto at = static_cast<size_t>((y.kind == ir::YieldKind::EmitRate ? l.emitRate(y.index) : l.emitCount(y.index)) - l.emits);
        l.writes[at] = true;
        const ir::Inst& value = kernel.at(y.value);
        using From = ColumnLayout::Shared::From;
        if (value.op == ir::Op::Const) l.emitShared[at] = {From::Constant, 0, value.constant[0]};
        if (value.op == ir::Op::Extern) l.emitShared[at] = {From::Extern, value.attr, 0};
        if (value.op == ir::Op::Uniform) l.emitShared[at] = {From::Uniform, value.attr, 0};
    }
    if (kernel.kind == ir::KernelKind::Render) {  // writes every render column (visible: drawn or not)…
        l.renderFromState.assign(ColumnLayout::kRenderColumns, -1);
        for (const ir::Yield& y : kernel.yields) {  // …but those that are state values as they are
            const ir::Inst& value = kernel.at(y.value);
            if (y.kind == ir::YieldKind::Visible || value.op != ir::Op::StateRead ||
                (y.kind != ir::YieldKind::Position && y.kind != ir::YieldKind::Color && y.kind != ir::YieldKind::Size))
                continue;
            for (int c = 0; c < value.type.width; ++c)
                l.renderFromState[static_cast<size_t>(ColumnLayout::renderColumn(y.kind) + c)] =
                    l.stateOffset.at(static_cast<size_t>(value.attr)) + c;
        }
        l.renderConstant.assign(ColumnLayout::kRenderColumns, {});
        for (const ir::Yield& y : kernel.yields)
            if (y.kind == ir::YieldKind::Position || y.kind == ir::YieldKind::Color || y.kind == ir::YieldKind::Size) {
                int first = ColumnLayout::renderColumn(y.kind);
                for (int c = 0; c < kernel.at(y.value).type.width; ++c)
                    if (auto v = constantLane(kernel, y.value, c))
                        l.renderConstant[static_cast<size_t>(first + c)] = {true, *v};
            }
        for (int c = 0; c < ColumnLayout::kRenderColumns; ++c)
            l.writes[static_cast<size_t>(l.render - l.emits + c)] =
                l.renderFromState[static_cast<size_t>(c)] < 0 && !l.renderConstant[static_cast<size_t>(c)].is;
    }
    for (const ir::Inst& i : kernel.insts()) {
        if (!ir::readsAncestor(i.op)) continue;
        l.parentColumns.push_back({i.op, i.attr2, i.op == ir::Op::ParentExport ? i.attr : -1, i.type.width, next});
        next += i.type.width;
    }
    l.total = next;
    return l;
}

ArgumentColumns argumentColumns(const ir::Kernel& spawn) {
    ArgumentColumns a;
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
    return a;
}

int ColumnLayout::renderColumn(ir::YieldKind kind) {
    switch (kind) {
        case ir::YieldKind::Visible: return kVisible;
        case ir::YieldKind::Position: return kPosition;
        case ir::YieldKind::Color: return kColor;
        default: return kSize;
    }
}

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
