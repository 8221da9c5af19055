#include <algorithm>
#include <cstring>

#include "ir/ir.h"

#include <fmt/format.h>

namespace psys::ir {
namespace {

// The hash-consing key: everything but the name.
std::string keyOf(const Inst& inst) {
    std::string key;
    auto put = [&](const void* p, size_t n) { key.append(static_cast<const char*>(p), n); };
    put(&inst.op, sizeof inst.op);
    put(&inst.type, sizeof inst.type);
    put(&inst.attr, sizeof inst.attr);
    put(&inst.attr2, sizeof inst.attr2);
    if (inst.op == Op::Const) put(inst.constant.data(), sizeof(float) * 4);
    for (ValueId v : inst.operands) put(&v, sizeof v);
    key.push_back('|');
    for (uint8_t l : inst.lanes) key.push_back(static_cast<char>(l));
    return key;
}

}  // namespace

bool Inst::sameAs(const Inst& other) const {
    return op == other.op && type == other.type && operands == other.operands && attr == other.attr &&
           attr2 == other.attr2 && lanes == other.lanes &&
           (op != Op::Const || std::memcmp(constant.data(), other.constant.data(), sizeof(float) * 4) == 0);
}

ValueId Kernel::add(Inst inst) {
    if (!inst.loc.valid()) inst.loc = loc_;
    if (isCommutative(inst.op) && inst.operands.size() == 2 && inst.operands[0] > inst.operands[1])
        std::swap(inst.operands[0], inst.operands[1]);
    if (hasOwnSite(inst.op)) return addUnique(std::move(inst));
    std::string key = keyOf(inst);
    if (auto it = table_.find(key); it != table_.end()) {
        if (insts_[it->second].name.empty()) insts_[it->second].name = inst.name;
        return it->second;
    }
    auto id = static_cast<ValueId>(insts_.size());
    table_.emplace(std::move(key), id);
    insts_.push_back(std::move(inst));
    return id;
}

ValueId Kernel::addUnique(Inst inst) {
    if (!inst.loc.valid()) inst.loc = loc_;
    auto id = static_cast<ValueId>(insts_.size());
    insts_.push_back(std::move(inst));
    return id;
}

ValueId Kernel::constant(Type type, std::array<float, 4> value) {
    Inst inst;
    inst.op = Op::Const;
    inst.type = type;
    for (int i = type.width; i < 4; ++i) value[static_cast<size_t>(i)] = 0;
    inst.constant = value;
    return add(std::move(inst));
}

ValueId Kernel::op(Op op, Type type, std::vector<ValueId> operands, int32_t attr) {
    Inst inst;
    inst.op = op;
    inst.type = type;
    inst.operands = std::move(operands);
    inst.attr = attr;
    return add(std::move(inst));
}

std::vector<const Yield*> Kernel::find(YieldKind kind, int index) const {
    std::vector<const Yield*> out;
    for (const Yield& y : yields)
        if (y.kind == kind && (index < 0 || y.index == index)) out.push_back(&y);
    return out;
}

const Yield* Kernel::findOne(YieldKind kind, int index, int sub) const {
    for (const Yield& y : yields)
        if (y.kind == kind && y.index == index && y.sub == sub) return &y;
    return nullptr;
}

void Kernel::rehash() {
    table_.clear();
    for (ValueId v = 0; v < insts_.size(); ++v)
        if (!hasOwnSite(insts_[v].op)) table_.emplace(keyOf(insts_[v]), v);
}

const Kernel* Object::kernel(KernelKind kind, int site) const {
    for (const Kernel& k : kernels)
        if (k.kind == kind && ((kind != KernelKind::Spawn && kind != KernelKind::Pair) || k.site == site)) return &k;
    return nullptr;
}

Kernel* Object::kernel(KernelKind kind, int site) {
    return const_cast<Kernel*>(static_cast<const Object*>(this)->kernel(kind, site));
}

std::optional<KernelKind> uniformFor(KernelKind kind) {
    switch (kind) {
        case KernelKind::Update: return KernelKind::UniformUpdate;
        case KernelKind::Render: return KernelKind::UniformRender;
        case KernelKind::Exports: return KernelKind::UniformExports;
        default: return std::nullopt;
    }
}

const Object* Module::object(const std::string& name) const {
    int i = objectIndex(name);
    return i < 0 ? nullptr : &objects[static_cast<size_t>(i)];
}

int Module::objectIndex(const std::string& name) const {
    for (size_t i = 0; i < objects.size(); ++i)
        if (objects[i].name == name) return static_cast<int>(i);
    return -1;
}

int Module::externIndex(const std::string& name) const {
    for (size_t i = 0; i < externs.size(); ++i)
        if (externs[i].name == name) return static_cast<int>(i);
    return -1;
}

namespace {
constexpr std::pair<EmitSite::When, std::string_view> kEmitWhenNames[] = {
    {EmitSite::When::Creation, "burst"},
    {EmitSite::When::Rate, "rate"},
    {EmitSite::When::Edge, "edge"},
    {EmitSite::When::Death, "death"},
};
}  // namespace

std::string_view emitWhenName(EmitSite::When when) {
    for (auto& [w, name] : kEmitWhenNames)
        if (w == when) return name;
    return "?";
}

std::optional<EmitSite::When> emitWhenFromName(std::string_view name) {
    for (auto& [w, n] : kEmitWhenNames)
        if (n == name) return w;
    return std::nullopt;
}

const char* kernelName(KernelKind kind) {
    switch (kind) {
        case KernelKind::Behaviour: return "behaviour";
        case KernelKind::Init: return "init";
        case KernelKind::Update: return "update";
        case KernelKind::Render: return "render";
        case KernelKind::Exports: return "exports";
        case KernelKind::Spawn: return "spawn";
        case KernelKind::Trigger: return "trigger";
        case KernelKind::Start: return "start";
        case KernelKind::Pair: return "pair";
        case KernelKind::UniformUpdate: return "uniform.update";
        case KernelKind::UniformRender: return "uniform.render";
        case KernelKind::UniformExports: return "uniform.exports";
    }
    return "?";
}

std::string drawnColumnName(int column) {
    static const char* const names[kDrawnColumns] = {"visible", "position.x", "position.y", "position.z", "color.r",
                                                     "color.g", "color.b", "color.a", "size", "rotation",
                                                     "frame", "end.x", "end.y", "end.z"};
    if (column >= kDrawnColumns)
        return fmt::format("trail.{}.{}", (column - kDrawnColumns) / 3 + 1, "xyz"[(column - kDrawnColumns) % 3]);
    return column >= 0 ? names[column] : "?";
}

std::string unexpectedOp(const Inst& inst, std::string_view backend) {
    std::string where = inst.loc.valid() ? " (the instruction from line " + std::to_string(inst.loc.line) + ", column " +
                                               std::to_string(inst.loc.column) + ")"
                                         : "";
    return "internal error: " + std::string(backend) + " has no code for `" + std::string(opInfo(inst.op).name) + "`" +
           where;
}

void defaultDrawn(Kernel& render) {
    KernelStorage& st = render.storage;
    if (render.kind != KernelKind::Render || !st.fixed) return;
    st.drawn.resize(std::max(st.drawn.size(), static_cast<size_t>(kDrawnColumns)));
    std::vector<bool> yielded(st.drawn.size(), false);
    for (const Yield& y : render.yields)
        if (isDrawnYield(y.kind))
            for (int c = 0; c < render.at(y.value).type.width; ++c)
                if (auto column = static_cast<size_t>(drawnColumn(y.kind, y.index) + c); column < yielded.size())
                    yielded[column] = true;
    for (int c = 0; c < kDrawnColumns; ++c)
        if (drawnDefaultsToZero(c) && !yielded[static_cast<size_t>(c)])
            st.drawn[static_cast<size_t>(c)] = {KernelStorage::Drawn::From::Constant, 0, 0, 0.0f};
}

}  // namespace psys::ir
