// ir::Evaluator's batches (the interpreter hands it rows a few dozen at a time): each row
// of a batch gives, bit for bit, what it gives evaluated alone — over every kernel of every
// sample and test program, optimized and not, with inputs that differ from row to row.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstring>

#include "core/instances.h"
#include "ir/evaluate.h"
#include "run.h"

using namespace psys;

namespace {

// Every input a kernel may read, different for each row: drawn from `seed`.
struct RowInputs {
    std::vector<ir::Value> params, state, externs, uniforms, parents, self, other;
    ir::KernelInputs in;

    RowInputs(const ir::Kernel& kernel, uint32_t seed) {
        uint32_t x = seed * 2654435761u + 1;
        auto next = [&x] {
            x = x * 1664525u + 1013904223u;
            return x;
        };
        auto value = [&] {
            ir::Value v;
            for (float& f : v.f) f = static_cast<float>(next() >> 8) / 4194304.0f - 2.0f;  // [-2, 2)
            v.u = next();
            return v;
        };
        std::vector<int> tables;  // where instance tables start among the externs
        auto fill = [&](std::vector<ir::Value>& to, int index) {
            if (to.size() <= static_cast<size_t>(index)) to.resize(static_cast<size_t>(index) + 1);
        };
        for (const ir::Inst& i : kernel.insts()) {
            switch (i.op) {
                case ir::Op::Param: case ir::Op::TriggerParam: fill(params, i.attr); break;
                case ir::Op::StateRead: fill(state, i.attr); break;
                case ir::Op::Extern: fill(externs, i.attr); break;
                case ir::Op::Uniform: fill(uniforms, i.attr); break;
                case ir::Op::NeighbourExport: fill(i.attr2 ? other : self, i.attr); break;
                case ir::Op::Instance:  // (its table among the externs: a count, then 3 records)
                    tables.push_back(i.attr2);
                    fill(externs, i.attr2 + 3 * static_cast<int>(core::instanceRecordValues(static_cast<size_t>(i.attr2))));
                    break;
                default: break;
            }
        }
        parents.resize(ir::parentReads(kernel).size());
        for (auto* v : {&params, &state, &externs, &uniforms, &parents, &self, &other})
            for (ir::Value& each : *v) each = value();
        for (int t : tables) externs[static_cast<size_t>(t)].f[0] = 3;
        in.params = params.data();
        in.state = state.data();
        in.externs = externs.data();
        in.uniforms = uniforms.data();
        in.parents = parents.data();
        in.self = self.data();
        in.other = other.data();
        in.age = static_cast<float>(next() % 4096) / 1024.0f;
        in.dt = static_cast<float>(next() % 64 + 1) / 1024.0f;
        in.time = in.age + static_cast<float>(next() % 1024) / 64.0f;
        in.first = next() % 2 == 0;
        in.seed = next();
        in.objectId = next() % 100000;
        in.draw = next() % 1000;
        in.childDraw = next() % 1000;
    }
};

bool sameBits(const ir::Value& a, const ir::Value& b) {
    return std::memcmp(a.f.data(), b.f.data(), sizeof a.f) == 0 && a.u == b.u;
}

}  // namespace

TEST_CASE("a batch of rows evaluates each row as alone, bit for bit, on every kernel of every sample") {
    constexpr size_t kRows = 37;  // not a power of two; the interpreter's batch is 64
    ir::Evaluator batch, alone;   // one evaluator each for every kernel: registers reused
    size_t kernels = 0;
    for (bool optimize : {true, false})
        for (const std::string& source : test::samplesAndPrograms()) {
            ir::Module m = test::compileModule(source, optimize);
            for (const ir::Object& o : m.objects)
                for (const ir::Kernel& kernel : o.kernels) {
                    ++kernels;
                    std::vector<RowInputs> rows;
                    std::vector<ir::KernelInputs> inputs;
                    for (size_t r = 0; r < kRows; ++r) rows.emplace_back(kernel, static_cast<uint32_t>(kernels * 100 + r));
                    for (const RowInputs& r : rows) inputs.push_back(r.in);
                    std::vector<ir::Value> together, one;
                    batch.run(kernel, inputs, together);
                    REQUIRE(together.size() == kernel.yields.size() * kRows);
                    size_t differ = 0;
                    for (size_t r = 0; r < kRows; ++r) {
                        alone.run(kernel, inputs[r], one);
                        for (size_t y = 0; y < kernel.yields.size(); ++y)
                            differ += sameBits(together[y * kRows + r], one[y]) ? 0 : 1;
                    }
                    INFO(o.name, " ", ir::kernelName(kernel.kind));
                    CHECK(differ == 0);
                }
        }
    CHECK(kernels > 100);
}
