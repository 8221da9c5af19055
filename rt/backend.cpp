#include "rt/backend.h"

namespace psys::rt {

namespace {

float* floats(const RowBatch& b, int column) { return static_cast<float*>(b.columns[column]); }

Value gather(const RowBatch& b, int column, int width, size_t row) {
    Value v;
    for (int c = 0; c < width; ++c) v.f[static_cast<size_t>(c)] = floats(b, column + c)[row];
    return v;
}

void scatter(const RowBatch& b, int column, int width, size_t row, const Value& v) {
    for (int c = 0; c < width; ++c) floats(b, column + c)[row] = v.f[static_cast<size_t>(c)];
}

}  // namespace

void Backend::runChildren(const ir::Kernel& spawn, const KernelInputs& in, uint32_t firstChild, size_t count,
                          Value* args, size_t stride) {
    KernelInputs child = in;
    std::vector<Value> yields;
    for (size_t k = 0; k < count; ++k) {
        child.childDraw = firstChild + static_cast<uint32_t>(k);
        run(spawn, child, yields);
        for (size_t i = 0; i < spawn.yields.size(); ++i)
            if (spawn.yields[i].kind == ir::YieldKind::EmitArg)
                args[k * stride + static_cast<size_t>(spawn.yields[i].sub)] = yields[i];
    }
}

// Row by row through `run`: the reference for what a compiled loop must compute.
void Backend::runRows(const ir::Object& object, const ir::Kernel& kernel, const BatchLayout& layout,
                      const RowBatch& batch) {
    std::vector<Value> params(object.params.size()), state(object.state.size()), yields, uniformValues, uniforms;
    const auto* created = static_cast<const double*>(batch.columns[BatchLayout::kCreated]);
    const auto* ids = static_cast<const uint32_t*>(batch.columns[BatchLayout::kIds]);
    // The kill column is written only by kernels that can kill.
    uint8_t* kill = nullptr;
    for (const ir::Yield& y : kernel.yields)
        if (y.kind == ir::YieldKind::Kill) kill = static_cast<uint8_t*>(batch.columns[BatchLayout::kKill]);
    for (size_t row = batch.begin; row < batch.end; ++row) {
        if (kill) kill[row] = 0;
        if (!batch.mask[row]) continue;
        for (size_t p = 0; p < params.size(); ++p)
            params[p] = batch.columns[layout.paramOffset[p]]
                            ? gather(batch, layout.paramOffset[p], object.params[p].type.width, row)
                            : Value{};
        for (size_t s = 0; s < state.size(); ++s)
            state[s] = gather(batch, layout.stateOffset[s], object.state[s].type.width, row);
        KernelInputs in;
        in.params = params.data();
        in.state = state.data();
        in.externs = batch.externs;
        in.uniforms = batch.uniforms;
        double time = batch.mode == RowsMode::Init ? created[row] : batch.time;
        in.age = static_cast<float>(time - created[row]);
        in.dt = batch.mode == RowsMode::FirstUpdate ? in.age : batch.dt;
        in.time = static_cast<float>(time);
        in.first = batch.mode == RowsMode::Init;
        in.seed = batch.seed;
        in.objectId = ids[row];
        in.draw = batch.draw;
        auto column = [&layout](ir::Op op, int depth, int exportIndex) {
            for (const auto& p : layout.parentColumns)
                if (p.op == op && p.depth == depth && p.exportIndex == exportIndex) return &p;
            return static_cast<const BatchLayout::ParentColumn*>(nullptr);
        };
        if (!layout.parentColumns.empty()) {
            in.parentExport = [&](int depth, int e) {
                auto* p = column(ir::Op::ParentExport, depth, e);
                return p ? gather(batch, p->offset, p->width, row) : Value{};
            };
            in.parentAlive = [&](int depth) {
                auto* p = column(ir::Op::ParentAlive, depth, -1);
                return p && floats(batch, p->offset)[row] != 0;
            };
            in.parentAge = [&](int depth) {
                auto* p = column(ir::Op::ParentAge, depth, -1);
                return p ? floats(batch, p->offset)[row] : 0.0f;
            };
        }
        if (batch.mode == RowsMode::FirstUpdate && batch.uniformKernel) {
            // The uniform values for this object's dt, as System::uniforms computes them.
            KernelInputs u;
            u.externs = batch.externs;
            u.dt = in.dt;
            u.time = in.time;
            u.seed = batch.seed;
            run(*batch.uniformKernel, u, uniformValues);
            uniforms.assign(uniformValues.size(), Value{});
            for (size_t i = 0; i < batch.uniformKernel->yields.size(); ++i)
                uniforms.at(static_cast<size_t>(batch.uniformKernel->yields[i].index)) = uniformValues[i];
            in.uniforms = uniforms.data();
        }
        run(kernel, in, yields);
        for (size_t i = 0; i < kernel.yields.size(); ++i) {
            const ir::Yield& y = kernel.yields[i];
            const Value& v = yields[i];
            int width = kernel.at(y.value).type.width;
            switch (y.kind) {
                case ir::YieldKind::StateNext: scatter(batch, layout.stateOffset[static_cast<size_t>(y.index)], width, row, v); break;
                case ir::YieldKind::Export: scatter(batch, layout.exportOffset[static_cast<size_t>(y.index)], width, row, v); break;
                case ir::YieldKind::Kill: if (kill) kill[row] = v.truth() ? 1 : 0; break;
                case ir::YieldKind::EmitRate: floats(batch, layout.emitRate(y.index))[row] = v.f[0]; break;
                case ir::YieldKind::EmitCount: floats(batch, layout.emitCount(y.index))[row] = v.f[0]; break;
                case ir::YieldKind::Visible: floats(batch, layout.render + BatchLayout::kVisible)[row] = v.f[0]; break;
                case ir::YieldKind::Position: scatter(batch, layout.render + BatchLayout::kPosition, 3, row, v); break;
                case ir::YieldKind::Color: scatter(batch, layout.render + BatchLayout::kColor, 4, row, v); break;
                case ir::YieldKind::Size: floats(batch, layout.render + BatchLayout::kSize)[row] = v.f[0]; break;
                default: break;
            }
        }
    }
}

}  // namespace psys::rt
