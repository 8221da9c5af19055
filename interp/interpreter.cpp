#include "interp/interpreter.h"

#include <algorithm>
#include <stdexcept>

#include "core/few.h"
#include "rt/clock.h"

namespace psys::interp {

using namespace ir;
using rt::Buffer;
using rt::ColumnLayout;

// The columns of a launch's table on host memory, their addresses looked up once.
// (On the stack up to 96: core/few.h, a launch allocates nothing on whatever thread runs it.)
struct Columns {
    core::Few<void*, 96> address;

    Columns(rt::Memory& memory, std::span<const Buffer> table) : address(table.size()) {
        for (size_t i = 0; i < table.size(); ++i) address[i] = table[i].valid() ? memory.host(table[i]) : nullptr;
    }
    float* floats(int column) const { return static_cast<float*>(address[static_cast<size_t>(column)]); }
    Value gather(int column, int width, size_t row) const {
        Value v;
        for (int c = 0; c < width; ++c) v.f[static_cast<size_t>(c)] = floats(column + c)[row];
        return v;
    }
    void scatter(int column, int width, size_t row, const Value& v) const {
        for (int c = 0; c < width; ++c) floats(column + c)[row] = v.f[static_cast<size_t>(c)];
    }
    // Every parameter (a column-less one, not kept by the pool, reads 0) and every slot.
    void inputs(const Object& o, const ColumnLayout& l, size_t row, Value* params, Value* state) const {
        for (size_t p = 0; p < o.params.size(); ++p)
            params[p] = address[static_cast<size_t>(l.paramOffset[p])] ? gather(l.paramOffset[p], o.params[p].type.width, row)
                                                                        : Value{};
        for (size_t s = 0; s < o.state.size(); ++s) state[s] = gather(l.stateOffset[s], o.state[s].type.width, row);
    }
};

void Interpreter::prepare(const rt::Plan& plan) {
    auto check = [](const Kernel* kernel) {
        if (!kernel) return;
        for (const Inst& i : kernel->insts())
            if (!evaluates(i.op)) throw std::runtime_error(unexpectedOp(i, "the interpreter"));
    };
    for (const rt::Plan::Rows& r : plan.rows) check(r.kernel);
    for (const rt::Plan::Children& c : plan.children) check(c.spawn);
}

rt::BackendReport Interpreter::report() const {
    rt::BackendReport r;
    r.target = "interpreter";
    return r;
}

// What one row's kernel yields: to its columns, its kill flag and the launch's counts.
void Interpreter::store(const rt::RowsLaunch& launch, const Columns& columns, uint8_t* kill, size_t row,
                        size_t batchRow, size_t batchSize, rt::RowsResult& result) const {
    const Kernel& kernel = *launch.kernel;
    const ColumnLayout& l = *launch.layout;
    for (size_t i = 0; i < kernel.yields.size(); ++i) {
        const Yield& y = kernel.yields[i];
        const Value& v = yields_[i * batchSize + batchRow];
        int width = kernel.at(y.value).type.width;
        switch (y.kind) {
            case YieldKind::StateNext: columns.scatter(l.stateOffset[static_cast<size_t>(y.index)], width, row, v); break;
            case YieldKind::Export: columns.scatter(l.exportOffset[static_cast<size_t>(y.index)], width, row, v); break;
            case YieldKind::Kill:
                kill[row] = v.truth() ? 1 : 0;
                result.killed += kill[row];
                break;
            case YieldKind::Unstable: result.unstable += v.truth() ? 1 : 0; break;
            case YieldKind::EmitRate: columns.floats(l.emitRate(y.index))[row] = v.f[0]; break;
            case YieldKind::EmitCount: columns.floats(l.emitCount(y.index))[row] = v.f[0]; break;
            case YieldKind::Visible: case YieldKind::Position: case YieldKind::Color: case YieldKind::Size:
            case YieldKind::Rotation: case YieldKind::Frame: case YieldKind::End: case YieldKind::Trail:
                if (l.fromState(y)) break;  // drawn from the state column itself
                if (y.kind == YieldKind::Visible) {
                    columns.floats(l.render + ColumnLayout::kVisible)[row] = v.truth() ? 1.0f : 0.0f;
                    break;
                }
                for (int c = 0; c < width; ++c)  // a constant lane has no column
                    if (int column = ColumnLayout::renderColumn(y.kind, y.index) + c; !l.constant(column))
                        columns.floats(l.render + column)[row] = v.f[static_cast<size_t>(c)];
                break;
            default: break;
        }
    }
}

// Row by row, as the reference for what a compiled loop must compute; evaluated
// kBatch masked rows at a time (ir::Evaluator's batches), each row exactly as alone.
rt::RowsResult Interpreter::run(const rt::RowsLaunch& launch) {
    const Object& o = *launch.object;
    const Kernel& kernel = *launch.kernel;
    const ColumnLayout& l = *launch.layout;
    Columns columns(*memory_, launch.columns);
    const auto* created = rt::hostData<double>(*memory_, launch.columns[ColumnLayout::kCreated]);
    const auto* ids = rt::hostData<uint32_t>(*memory_, launch.columns[ColumnLayout::kIds]);
    const auto* mask = rt::hostData<uint8_t>(*memory_, launch.mask);
    const rt::Clock& clock = launch.clock;
    const double* nows = clock.now == rt::Clock::Source::PerRow
                             ? rt::hostData<double>(*memory_, launch.columns[ColumnLayout::kNow])
                             : nullptr;
    const float* dts = clock.dt == rt::Clock::Source::PerRow
                           ? rt::hostData<float>(*memory_, launch.columns[ColumnLayout::kDt])
                           : nullptr;
    // The kill column is written only by kernels that can kill.
    uint8_t* kill = nullptr;
    for (const Yield& y : kernel.yields)
        if (y.kind == YieldKind::Kill) kill = rt::hostData<uint8_t>(*memory_, launch.columns[ColumnLayout::kKill]);
    const Kernel* uniformKernel = clock.perRow() ? launch.uniformKernel : nullptr;  // each row's own uniform values
    const size_t nParams = o.params.size(), nState = o.state.size(), nParents = l.parentColumns.size();
    const size_t nUniforms = uniformKernel ? uniformKernel->yields.size() : 0;
    params_.resize(kBatch * nParams);
    state_.resize(kBatch * nState);
    parents_.resize(kBatch * nParents);
    uniforms_.resize(kBatch * nUniforms);
    rt::RowsResult result;
    std::vector<size_t>& batch = batchRows_;
    auto flush = [&] {
        const size_t n = batch.size();
        inputs_.assign(n, KernelInputs{});
        for (size_t j = 0; j < n; ++j) {
            size_t row = batch[j];
            columns.inputs(o, l, row, params_.data() + j * nParams, state_.data() + j * nState);
            for (size_t p = 0; p < nParents; ++p)
                parents_[j * nParents + p] = columns.gather(l.parentColumns[p].offset, l.parentColumns[p].width, row);
            double now = nows ? nows[row] : clock.nowValue;
            KernelInputs& in = inputs_[j];
            in.params = params_.data() + j * nParams;
            in.state = state_.data() + j * nState;
            in.externs = launch.externs;
            in.uniforms = launch.uniforms;
            in.parents = parents_.data() + j * nParents;
            in.age = rt::ageAt(now, created[row]);
            in.dt = dts ? dts[row] : clock.dt == rt::Clock::Source::SinceCreated ? in.age : clock.dtValue;
            in.time = static_cast<float>(now);
            in.first = clock.first;
            in.seed = launch.seed;
            in.objectId = ids[row];
            in.draw = launch.draw;
        }
        if (uniformKernel) {
            uniformInputs_.assign(n, KernelInputs{});
            for (size_t j = 0; j < n; ++j) {
                KernelInputs& u = uniformInputs_[j];
                u.externs = launch.externs;
                u.dt = inputs_[j].dt;
                u.time = inputs_[j].time;
                u.seed = launch.seed;
            }
            evaluator_.run(*uniformKernel, uniformInputs_, yields_);
            for (size_t j = 0; j < n; ++j) {
                for (size_t i = 0; i < nUniforms; ++i)
                    uniforms_.at(j * nUniforms + static_cast<size_t>(uniformKernel->yields[i].index)) = yields_[i * n + j];
                inputs_[j].uniforms = uniforms_.data() + j * nUniforms;
            }
        }
        evaluator_.run(kernel, inputs_, yields_);
        for (size_t j = 0; j < n; ++j) store(launch, columns, kill, batch[j], j, n, result);
        batch.clear();
    };
    batch.clear();
    for (size_t row = launch.begin; row < launch.end; ++row) {
        if (kill) kill[row] = 0;
        if (!mask[row]) continue;
        batch.push_back(row);
        if (batch.size() == kBatch) flush();
    }
    if (!batch.empty()) flush();
    return result;
}

// A spawn kernel once per child: its arguments go to the argument columns, one per
// component of each parameter, in parameter order.
void Interpreter::run(const rt::ChildrenLaunch& launch) {
    const Kernel& spawn = *launch.spawn;
    Columns columns(*memory_, launch.columns);
    params_.resize(launch.object->params.size());
    state_.resize(launch.object->state.size());
    columns.inputs(*launch.object, *launch.layout, launch.row, params_.data(), state_.data());
    const auto* created = rt::hostData<double>(*memory_, launch.columns[ColumnLayout::kCreated]);
    const auto* ids = rt::hostData<uint32_t>(*memory_, launch.columns[ColumnLayout::kIds]);
    rt::argumentColumns(spawn, arguments_);
    const std::vector<size_t>& firstColumn = arguments_.first;
    KernelInputs in;
    in.params = params_.data();
    in.state = state_.data();
    in.externs = launch.externs;
    in.parents = launch.parents;
    in.age = rt::ageAt(launch.clock.nowValue, created[launch.row]);
    in.dt = launch.clock.dtValue;
    in.time = static_cast<float>(launch.clock.nowValue);
    in.first = launch.clock.first;
    in.seed = launch.seed;
    in.objectId = ids[launch.row];
    in.draw = launch.draw;
    for (size_t first = 0; first < launch.count; first += kBatch) {
        const size_t n = std::min(kBatch, launch.count - first);
        inputs_.assign(n, in);
        for (size_t j = 0; j < n; ++j) inputs_[j].childDraw = launch.firstChild + static_cast<uint32_t>(first + j);
        evaluator_.run(spawn, inputs_, yields_);
        for (size_t i = 0; i < spawn.yields.size(); ++i) {
            const Yield& y = spawn.yields[i];
            if (y.kind != YieldKind::EmitArg) continue;
            size_t column = firstColumn[static_cast<size_t>(y.sub)];
            for (int c = 0; c < spawn.at(y.value).type.width; ++c) {
                float* arg = rt::hostData<float>(*memory_, launch.args[column + static_cast<size_t>(c)]);
                for (size_t j = 0; j < n; ++j)
                    arg[launch.argsFirst + first + j] = yields_[i * n + j].f[static_cast<size_t>(c)];
            }
        }
    }
}

}  // namespace psys::interp
