#include "ir/printer.h"

#include <fmt/format.h>

namespace psys::ir {
namespace {

std::string number(float x) {
    std::string s = fmt::format("{}", x);  // shortest form that reads back exactly
    return s;
}

std::string constantText(const Inst& inst) {
    std::string s;
    int n = inst.type.isFloat() ? inst.type.width : 1;
    for (int i = 0; i < n; ++i) s += (i ? " " : "") + number(inst.constant[static_cast<size_t>(i)]);
    return s;
}

std::string params(const std::vector<Param>& ps) {
    std::string s;
    for (auto& p : ps)
        s += (s.empty() ? "" : ", ") + p.name + ": " + p.type.str() + (p.spelling.empty() ? "" : " as " + p.spelling) +
             (p.kept ? "" : " once");
    return s;
}

std::string values(const std::array<float, 4>& v, Type t) {
    std::string s;
    for (int i = 0; i < t.width; ++i) s += (i ? " " : "") + number(v[static_cast<size_t>(i)]);
    return s;
}

// A kernel's storage record (KernelStorage), a line a fact, after its yields.
std::string storageText(const Kernel& kernel, const std::string& pad) {
    const KernelStorage& st = kernel.storage;
    if (!st.fixed) return "";
    std::string out = pad + "  storage\n";
    using Shared = KernelStorage::Shared;
    for (size_t c = 0; c < st.emits.size(); ++c) {
        const Shared& e = st.emits[c];
        if (e.from == Shared::From::Column) continue;
        out += fmt::format("{}  storage emit.{} #{} = ", pad, c % 2 ? "count" : "rate", c / 2);
        if (e.from == Shared::From::Constant) out += "const " + number(e.value) + "\n";
        if (e.from == Shared::From::Extern) out += fmt::format("extern #{}\n", e.index);
        if (e.from == Shared::From::Uniform) out += fmt::format("uniform #{}\n", e.index);
    }
    using Drawn = KernelStorage::Drawn;
    for (size_t c = 0; c < st.drawn.size(); ++c) {
        const Drawn& d = st.drawn[c];
        if (d.from == Drawn::From::Column) continue;
        bool yielded = false;  // (unyielded, past a point's: 0 without saying so; ir::defaultDrawn)
        for (const Yield& y : kernel.yields)
            yielded |= isDrawnYield(y.kind) && static_cast<int>(c) >= drawnColumn(y.kind, y.index) &&
                       static_cast<int>(c) < drawnColumn(y.kind, y.index) + kernel.at(y.value).type.width;
        if (drawnDefaultsToZero(static_cast<int>(c)) && !yielded) continue;
        out += fmt::format("{}  storage drawn {} = ", pad, drawnColumnName(static_cast<int>(c)));
        out += d.from == Drawn::From::State ? fmt::format("state #{}.{}\n", d.slot, d.lane) : "const " + number(d.value) + "\n";
    }
    for (const KernelStorage::ParentRead& p : st.parents)
        out += fmt::format("{}  storage parent {} #{} ^{} {}\n", pad, opInfo(p.op).name, p.exportIndex, p.depth, p.width);
    if (!st.zeroed.empty()) {
        out += pad + "  storage zeroed";
        for (int slot : st.zeroed) out += fmt::format(" #{}", slot);
        out += "\n";
    }
    return out;
}

}  // namespace

std::string yieldKindName(YieldKind kind) {
    switch (kind) {
        case YieldKind::StateNext: return "state";
        case YieldKind::Kill: return "kill";
        case YieldKind::Visible: return "visible";
        case YieldKind::Position: return "position";
        case YieldKind::Color: return "color";
        case YieldKind::Size: return "size";
        case YieldKind::Rotation: return "rotation";
        case YieldKind::Frame: return "frame";
        case YieldKind::End: return "end";
        case YieldKind::Trail: return "trail";
        case YieldKind::EmitRate: return "emit.rate";
        case YieldKind::EmitCount: return "emit.count";
        case YieldKind::EmitArg: return "emit.arg";
        case YieldKind::Export: return "export";
        case YieldKind::Uniform: return "uniform";
        case YieldKind::Fold: return "fold";
        case YieldKind::Unstable: return "unstable";
    }
    return "?";
}

std::string print(const Kernel& kernel, int indent, PrintOptions options) {
    std::string pad(static_cast<size_t>(indent), ' ');
    std::string out = pad + "kernel " + kernelName(kernel.kind);
    if (kernel.kind == KernelKind::Spawn || kernel.kind == KernelKind::Pair) out += fmt::format(" #{}", kernel.site);
    out += "\n";
    for (ValueId v = 0; v < kernel.size(); ++v) {
        const Inst& inst = kernel.at(v);
        std::string line = fmt::format("{}  %{} = {}.{}", pad, v, opInfo(inst.op).name, inst.type.str());
        if (inst.op == Op::Const) line += " " + constantText(inst);
        for (size_t i = 0; i < inst.operands.size(); ++i) line += fmt::format("{} %{}", i ? "," : "", inst.operands[i]);
        bool showAttr = inst.attr != 0 || inst.op == Op::Param || inst.op == Op::StateRead || inst.op == Op::Extern ||
                        inst.op == Op::TriggerParam || inst.op == Op::ParentRead || inst.op == Op::ParentExport ||
                        inst.op == Op::Extract || inst.op == Op::DrawIndex || inst.op == Op::Uniform ||
                        inst.op == Op::NeighbourRead || inst.op == Op::NeighbourExport || inst.op == Op::Fold ||
                        inst.op == Op::Instance ||
                        hasOwnSite(inst.op);
        if (showAttr) line += fmt::format(" #{}", inst.attr);
        if (inst.attr2 != 0) line += fmt::format(" ^{}", inst.attr2);
        if (!inst.lanes.empty()) {
            line += " <";
            for (size_t i = 0; i < inst.lanes.size(); ++i) line += fmt::format("{}{}", i ? " " : "", inst.lanes[i]);
            line += ">";
        }
        if (options.locations && inst.loc.valid()) {
            auto file = static_cast<size_t>(inst.loc.file);
            std::string path = options.files && file < options.files->size() ? (*options.files)[file]
                                                                             : fmt::format("#{}", file);
            line += fmt::format("  loc({}:{}:{})", path, inst.loc.line, inst.loc.column);
        }
        if (!inst.name.empty()) line += "  ; " + inst.name;
        out += line + "\n";
    }
    for (auto& [name, value] : kernel.equations) out += fmt::format("{}  let {} = %{}\n", pad, name, value);
    for (const Yield& y : kernel.yields) {
        std::string line = pad + "  yield " + yieldKindName(y.kind);
        bool indexed = y.kind == YieldKind::StateNext || y.kind == YieldKind::EmitRate ||
                       y.kind == YieldKind::EmitCount || y.kind == YieldKind::EmitArg || y.kind == YieldKind::Export ||
                       y.kind == YieldKind::Uniform || y.kind == YieldKind::Trail || y.kind == YieldKind::Fold;
        if (indexed) line += fmt::format(" #{}", y.index);
        if (y.kind == YieldKind::EmitArg) line += fmt::format(" #{}", y.sub);
        out += line + fmt::format(" = %{}\n", y.value);
    }
    return out + storageText(kernel, pad) + pad + "end\n";
}

std::string print(const Object& o, PrintOptions options) {
    std::string out = fmt::format("object {}({})\n", o.name, params(o.params));
    if (!o.parent.empty()) out += "  parent " + o.parent + "\n";
    const Attributes& a = o.attributes;
    if (a.integrator) out += fmt::format("  attribute integrator {}\n", core::integratorName(*a.integrator));
    if (a.step > 0) out += fmt::format("  attribute step {}\n", number(a.step));
    if (a.precision != Precision::Float) out += fmt::format("  attribute precision {}\n", precisionName(a.precision));
    if (a.tolerance > 0) out += fmt::format("  attribute tolerance {} {}\n", number(a.tolerance), number(a.toleranceOver));
    if (a.capacity) out += fmt::format("  attribute capacity {}\n", *a.capacity);
    if (a.shape) out += fmt::format("  attribute shape {}\n", core::shapeName(*a.shape));
    if (a.blend) out += fmt::format("  attribute blend {}\n", core::blendName(*a.blend));
    if (!a.texture.empty())  // (the path last: it may hold spaces)
        out += fmt::format("  attribute texture {} {} {}\n", a.textureColumns, a.textureRows, a.texture);
    if (o.draw == core::DrawKind::Trail) out += fmt::format("  draw trail {}\n", o.trail);
    else if (o.draw != core::DrawKind::Point) out += fmt::format("  draw {}\n", core::drawKindName(o.draw));
    for (auto& s : o.state)
        out += fmt::format("  state {}: {} {}\n", s.name, s.type.str(), s.init == StateInit::Zero ? "zero" : "next");
    for (auto& e : o.emits) out += fmt::format("  emit {} {}\n", e.target, emitWhenName(e.when));
    for (auto& e : o.exports) out += fmt::format("  export {}: {}\n", e.name, e.type.str());
    for (auto& r : o.parentReads) out += fmt::format("  read {}: {} ^{}\n", r.member, r.type.str(), r.depth);
    for (auto& g : o.neighbours) {
        out += fmt::format("  near {} {}", g.target, number(g.radius));
        if (g.selfPosition >= 0) out += fmt::format(" position #{} #{}", g.selfPosition, g.otherPosition);
        out += "\n";
    }
    for (auto& f : o.folds) out += fmt::format("  fold {}: {} #{}\n", core::reduceInfo(f.reduce).name, f.type.str(), f.group);
    for (auto& r : o.neighbourReads)
        out += fmt::format("  near.read {}: {} {}\n", r.member, r.type.str(), r.other ? "other" : "self");
    for (auto& k : o.kernels) out += print(k, 2, options);
    return out + "end\n";
}

std::string print(const Module& m, PrintOptions options) {
    if (!options.files) options.files = &m.files;
    std::string out;
    for (auto& e : m.externs) {
        out += fmt::format("extern {}: {} = {}", e.name, e.type.str(), values(e.defaultValue, e.type));
        if (e.low) out += fmt::format(" range {} to {}", values(*e.low, e.type), values(*e.high, e.type));
        if (!e.spelling.empty()) out += " as " + e.spelling;
        out += "\n";
    }
    for (auto& o : m.objects) out += print(o, options);
    auto trigger = [&](const Trigger& t, const std::string& head) {
        out += head + "\n";
        for (auto& e : t.emits) out += fmt::format("  emit {} {}\n", e.target, emitWhenName(e.when));
        out += print(t.kernel, 2, options);
        out += "end\n";
    };
    for (auto& t : m.triggers) trigger(t, fmt::format("trigger {}({})", t.name, params(t.params)));
    // (An instanced program's start has its hidden parameter: `start(instance: f32)`.)
    if (!m.start.emits.empty() || m.start.kernel.size() > 0 || !m.start.params.empty())
        trigger(m.start, m.start.params.empty() ? std::string("start") : fmt::format("start({})", params(m.start.params)));
    return out;
}

}  // namespace psys::ir
