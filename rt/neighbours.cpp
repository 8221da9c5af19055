// The neighbour folds (docs/language.md, "Neighbours"): once a step, before any update,
// each type's folds over the objects near each of its objects — so that every object sees
// the others as the last step left them, whatever order the types update in.
//
// A backend may fold on its own side (Backend::fold: the GPU); else the run-time folds
// here, on the host: a grid of the other type's drawn positions — cells the radius (and a
// little) wide, hashed into buckets (core/hash.h cellBucket), its rows counting-sorted by
// bucket in row order — then, for each object, the buckets of the 27 cells around its
// own in bucket order, each bucket's rows in row order. That is the order terms are
// combined in, so the folds do not depend on the number of threads. The walk of those
// buckets and the terms are the backend's compiled function (Backend::pairFunction), or
// the run-time's walk and the IR evaluated.
//
// The objects are walked in their own grid's order, not row order: the objects of one cell
// read the same 27 buckets (found once for them) one after another, so a bucket is read
// from memory once for a cell rather than once for each object in it — at 10⁶ objects
// walking by row waited on memory for most of its time. An object's folds are its own,
// whoever computes them when, so the order of the walk changes no bit of them.
#include <algorithm>
#include <cmath>

#include "core/fold.h"
#include "core/hash.h"
#include "rt/system_state.h"

namespace psys::rt::detail {

namespace {

constexpr size_t kFoldRows = 1024;  // objects a chunk of the host's fold

// A side's export columns as host arrays: the memory's own where it is the host's, else
// read (a device's memory: what the GPU does not fold itself).
struct HostSide {
    std::vector<const float*> columns;  // export e's component c at 4e + c
    std::vector<std::vector<float>> owned;
    const uint8_t* mask = nullptr;
    std::vector<uint8_t> ownedMask;

    HostSide(const Memory& memory, const FoldLaunch::Side& side) {
        auto read = [&](Buffer b, size_t bytes) -> const void* {
            if (const void* v = memory.view(b)) return v;
            auto& data = owned.emplace_back((side.rows * bytes + 3) / 4);
            if (side.rows) memory.read(b, 0, side.rows, data.data());
            return data.data();
        };
        for (const auto& e : side.exports)
            for (Buffer b : e) columns.push_back(b.valid() ? static_cast<const float*>(read(b, 4)) : nullptr);
        mask = static_cast<const uint8_t*>(read(side.mask, 1));
    }
};

// The other side's objects by bucket: rows and positions sorted by bucket, in row order
// within one.
struct Grid {
    float inverse = 1;  // 1 / the cell's width
    uint32_t mask = 0;  // buckets − 1
    std::vector<uint32_t> start, rows;
    std::vector<float> x, y, z;
    // The other side's export columns the terms read, in the grid's order (export e's
    // component c at 4e + c; null for the others): a bucket's terms read them in a row.
    std::vector<std::vector<float>> sorted;
    std::vector<const float*> columns;

    // Its arrays back to `buffers`, for the next step's grid.
    void keep(FoldBuffers& buffers) {
        buffers.start = std::move(start);
        buffers.rows = std::move(rows);
        buffers.x = std::move(x);
        buffers.y = std::move(y);
        buffers.z = std::move(z);
        buffers.sorted = std::move(sorted);
    }

    uint32_t cell(float p) const { return core::HostAlgebra::wholeToInt(std::floor(p * inverse)); }
    uint32_t bucket(uint32_t cx, uint32_t cy, uint32_t cz) const {
        core::HostAlgebra a;
        return core::cellBucket(a, cx, cy, cz, mask);
    }
};

// A side's live rows counting-sorted by the bucket of their position (row order within
// one) into `sorted`, with where each bucket starts into `start`.
void rowsByBucket(const Grid& g, const HostSide& side, size_t rows, int position, std::vector<uint32_t>& sorted,
                  std::vector<uint32_t>& bucketOf, std::vector<uint32_t>& count) {
    const float* px = side.columns[static_cast<size_t>(4 * position)];
    const float* py = side.columns[static_cast<size_t>(4 * position + 1)];
    const float* pz = side.columns[static_cast<size_t>(4 * position + 2)];
    bucketOf.resize(rows);
    count.assign(size_t{g.mask} + 2, 0);
    for (size_t r = 0; r < rows; ++r) {
        if (!side.mask[r]) continue;
        bucketOf[r] = g.bucket(g.cell(px[r]), g.cell(py[r]), g.cell(pz[r]));
        ++count[bucketOf[r] + 1];
    }
    for (uint32_t b = 0; b <= g.mask; ++b) count[b + 1] += count[b];
    sorted.resize(count.back());
    for (size_t r = 0; r < rows; ++r)
        if (side.mask[r]) sorted[count[bucketOf[r]]++] = static_cast<uint32_t>(r);
    // (count[b] is now where bucket b ends: where b + 1 starts)
    for (size_t b = count.size() - 1; b > 0; --b) count[b] = count[b - 1];
    count[0] = 0;
}

// The grid, its arrays `buffers`' (given back by keep()).
Grid buildGrid(const HostSide& other, size_t rows, int position, float radius, const ir::Kernel& pair,
               FoldBuffers& buffers) {
    Grid g;
    g.inverse = 1.0f / (radius * core::kCellMargin);
    g.mask = core::gridBuckets(rows) - 1;
    g.start = std::move(buffers.start);
    g.rows = std::move(buffers.rows);
    g.x = std::move(buffers.x);
    g.y = std::move(buffers.y);
    g.z = std::move(buffers.z);
    g.sorted = std::move(buffers.sorted);
    rowsByBucket(g, other, rows, position, g.rows, buffers.bucketOf, g.start);
    size_t n = g.rows.size();
    const float* px = other.columns[static_cast<size_t>(4 * position)];
    const float* py = other.columns[static_cast<size_t>(4 * position + 1)];
    const float* pz = other.columns[static_cast<size_t>(4 * position + 2)];
    g.x.resize(n);
    g.y.resize(n);
    g.z.resize(n);
    for (size_t j = 0; j < n; ++j) {
        g.x[j] = px[g.rows[j]];
        g.y[j] = py[g.rows[j]];
        g.z[j] = pz[g.rows[j]];
    }
    g.columns.assign(other.columns.size(), nullptr);
    size_t used = 0;  // of g.sorted
    for (const ir::Inst& i : pair.insts()) {
        if (i.op != ir::Op::NeighbourExport || i.attr2 != 1) continue;
        for (int c = 0; c < i.type.width; ++c) {
            auto column = static_cast<size_t>(4 * i.attr + c);
            if (g.columns[column]) continue;
            if (i.attr == position) {  // the positions: sorted already
                g.columns[column] = (c == 0 ? g.x : c == 1 ? g.y : g.z).data();
                continue;
            }
            if (used == g.sorted.size()) g.sorted.emplace_back();
            std::vector<float>& to = g.sorted[used++];
            to.resize(n);
            const float* from = other.columns[column];
            for (size_t j = 0; j < n; ++j) to[j] = from[g.rows[j]];
            g.columns[column] = to.data();
        }
    }
    return g;
}

// The terms of a pair kernel, evaluated (a backend without a compiled one).
class EvaluatedTerms {
public:
    EvaluatedTerms(const ir::Object& object, const ir::Kernel& pair, const Value* externs)
        : pair_(pair), externs_(externs), self_(object.exports.size()) {
        std::vector<size_t> offsets;
        size_t at = 0;
        for (const ir::Fold& f : object.folds) {
            offsets.push_back(at);
            if (f.group == pair.site) at += static_cast<size_t>(f.type.width);
        }
        for (const ir::Yield& y : pair.yields) {
            const ir::Fold& f = object.folds.at(static_cast<size_t>(y.index));
            folds_.push_back({offsets[static_cast<size_t>(y.index)], f.type.width, f.reduce});
        }
        for (const ir::Inst& i : pair.insts())
            if (i.op == ir::Op::NeighbourExport) reads_.push_back({i.attr2 == 1, i.attr, i.type.width});
        size_t otherExports = 0;
        for (const Read& r : reads_)
            if (r.other) otherExports = std::max(otherExports, static_cast<size_t>(r.exportIndex) + 1);
        otherWidth_ = otherExports;
    }

    // The terms of `count` others, evaluated kBatch at a time (ir::Evaluator's batches:
    // each as alone) and combined in the others' order.
    void operator()(const float* const* self, const float* const* other, uint32_t selfRow, const uint32_t* others,
                    uint32_t count, float* acc) {
        load(self, selfRow, false, self_.data());
        const size_t nOther = otherWidth_;
        for (uint32_t first = 0; first < count; first += kBatch) {
            const size_t n = std::min<size_t>(kBatch, count - first);
            other_.resize(n * nOther);
            inputs_.assign(n, ir::KernelInputs{});
            for (size_t k = 0; k < n; ++k) {
                load(other, others[first + k], true, other_.data() + k * nOther);
                inputs_[k].externs = externs_;
                inputs_[k].self = self_.data();
                inputs_[k].other = other_.data() + k * nOther;
            }
            evaluator_.run(pair_, inputs_, values_);
            for (size_t k = 0; k < n; ++k)
                for (size_t y = 0; y < folds_.size(); ++y)
                    for (int c = 0; c < folds_[y].width; ++c) {
                        float& a = acc[folds_[y].offset + static_cast<size_t>(c)];
                        a = core::combine(folds_[y].reduce, a, values_[y * n + k].f[static_cast<size_t>(c)]);
                    }
        }
    }

private:
    struct Read {
        bool other;
        int exportIndex, width;
    };
    static constexpr size_t kBatch = 64;  // others a batch of evaluations
    void load(const float* const* columns, uint32_t row, bool other, Value* out) const {
        for (const Read& r : reads_) {
            if (r.other != other) continue;
            for (int c = 0; c < r.width; ++c)
                out[static_cast<size_t>(r.exportIndex)].f[static_cast<size_t>(c)] =
                    columns[static_cast<size_t>(4 * r.exportIndex + c)][row];
        }
    }
    struct Term {
        size_t offset;
        int width;
        core::Reduce reduce;
    };
    const ir::Kernel& pair_;
    const Value* externs_;
    std::vector<Term> folds_;  // per yield
    std::vector<Read> reads_;
    std::vector<Value> self_, other_, values_;  // other_: kBatch others' exports, otherWidth_ each
    size_t otherWidth_ = 0;
    std::vector<ir::KernelInputs> inputs_;
    ir::Evaluator evaluator_;
};

}  // namespace

void State::foldOnHost(const FoldLaunch& launch) {
    const ir::Object& object = *launch.object;
    const ir::NeighbourGroup& group = *launch.group;
    HostSide self(memory, launch.self), other(memory, launch.other);
    FoldBuffers& buffers = foldBuffers;
    Grid grid = buildGrid(other, launch.other.rows, group.otherPosition, group.radius, *launch.pair, buffers);
    const float radius2 = group.radius * group.radius;

    // The group's folds: their components, in fold order, and where each fold's are.
    std::vector<const ir::Fold*> folds;
    std::vector<size_t> firstComponent;
    size_t width = 0;
    for (const ir::Fold& f : object.folds) {
        if (f.group != launch.pair->site) continue;
        folds.push_back(&f);
        firstComponent.push_back(width);
        width += static_cast<size_t>(f.type.width);
    }
    std::vector<float> empty;
    for (const ir::Fold* f : folds) empty.insert(empty.end(), static_cast<size_t>(f->type.width), core::emptyFold(f->reduce));
    const size_t rows = launch.self.rows;
    std::vector<float>& results = buffers.results;  // row by row
    results.resize((rows + 1) * width);
    for (size_t r = 0; r <= rows; ++r) std::copy(empty.begin(), empty.end(), results.begin() + static_cast<std::ptrdiff_t>(r * width));

    PairFunction compiled = backend.pairFunction(object, *launch.pair);
    const float* const* sx = self.columns.data();
    const float* const* ox = grid.columns.data();  // (by place in the grid, not by row)
    const size_t sp = static_cast<size_t>(4 * group.selfPosition);
    // The objects in their grid's order (the other side's grid where it is their own).
    if (!launch.same) rowsByBucket(grid, self, rows, group.selfPosition, buffers.order, buffers.bucketOf, buffers.orderStart);
    const std::vector<uint32_t>& order = launch.same ? grid.rows : buffers.order;
    size_t chunks = (order.size() + kFoldRows - 1) / kFoldRows;
    parallel->forEach(chunks, true, [&](size_t c) {
        std::optional<EvaluatedTerms> evaluated;
        if (!compiled) evaluated.emplace(object, *launch.pair, launch.externs);
        std::vector<uint32_t> candidates;
        uint32_t buckets[27];
        uint32_t cell[3] = {0, 0, 0};
        int n = 0;  // the buckets around `cell`; 0: none found yet
        for (size_t k = c * kFoldRows; k < std::min(order.size(), (c + 1) * kFoldRows); ++k) {
            const uint32_t i = order[k];
            float px = sx[sp][i], py = sx[sp + 1][i], pz = sx[sp + 2][i];
            uint32_t cx = grid.cell(px), cy = grid.cell(py), cz = grid.cell(pz);
            if (n == 0 || cx != cell[0] || cy != cell[1] || cz != cell[2]) {
                cell[0] = cx, cell[1] = cy, cell[2] = cz;
                n = 0;
                for (uint32_t dz = 0; dz < 3; ++dz)
                    for (uint32_t dy = 0; dy < 3; ++dy)
                        for (uint32_t dx = 0; dx < 3; ++dx) buckets[n++] = grid.bucket(cx + dx - 1, cy + dy - 1, cz + dz - 1);
                std::sort(buckets, buckets + n);
                n = static_cast<int>(std::unique(buckets, buckets + n) - buckets);
                size_t room = 0;
                for (int b = 0; b < n; ++b) room += grid.start[buckets[b] + 1] - grid.start[buckets[b]];
                if (candidates.size() < room) candidates.resize(room);
            }
            const auto self = launch.same ? i : kSkipRow;
            float* acc = results.data() + size_t{i} * width;
            if (compiled) {  // the walk compiled with the terms
                PairWalk walk{buckets, grid.start.data(), grid.x.data(), grid.y.data(), grid.z.data(), grid.rows.data(),
                              candidates.data(), static_cast<uint32_t>(n), self, px, py, pz, radius2};
                compiled(sx, ox, i, &walk, launch.externs, acc);
                continue;
            }
            // Each bucket's places kept where within the radius, without a branch per place
            // (a third of the candidates are kept: a branch would be mispredicted often).
            uint32_t count = 0;
            for (int b = 0; b < n; ++b)
                for (uint32_t j = grid.start[buckets[b]]; j < grid.start[buckets[b] + 1]; ++j) {
                    float dx = grid.x[j] - px, dy = grid.y[j] - py, dz = grid.z[j] - pz;
                    candidates[count] = j;
                    count += (dx * dx + dy * dy + dz * dz <= radius2) & (grid.rows[j] != self);
                }
            (*evaluated)(sx, ox, i, candidates.data(), count, acc);
        }
    });
    // Into the fold columns, component by component.
    std::vector<float>& column = buffers.column;
    column.resize(rows + 1);
    for (size_t k = 0; k < folds.size(); ++k) {
        auto index = static_cast<size_t>(folds[k] - object.folds.data());
        for (int comp = 0; comp < folds[k]->type.width; ++comp) {
            for (size_t r = 0; r <= rows; ++r) column[r] = results[r * width + firstComponent[k] + static_cast<size_t>(comp)];
            memory.write(launch.results[index][static_cast<size_t>(comp)], 0, rows + 1, column.data());
        }
    }
    grid.keep(buffers);
}

// Every group of a type's folds, over its objects alive before this step.
void State::foldNeighbours(size_t type) {
    Pool& pool = pools[type];
    const ir::Object& object = pool.object();
    size_t rows = pool.rows();
    pool.folds.resize(memory, rows + 1);
    pool.foldRows = rows;
    auto side = [&](Pool& p) {
        p.syncMasks();
        FoldLaunch::Side s;
        s.rows = p.rows();
        s.mask = p.updatable.column;
        for (size_t e = 0; e < p.exports.count(); ++e) {
            std::array<Buffer, 4> components{};
            for (int c = 0; c < p.exports.type(e).width; ++c) components[static_cast<size_t>(c)] = p.exports.column(e, static_cast<size_t>(c));
            s.exports.push_back(components);
        }
        return s;
    };
    for (const ir::Kernel& pair : object.kernels) {
        if (pair.kind != ir::KernelKind::Pair) continue;
        const ir::NeighbourGroup& group = object.neighbours.at(static_cast<size_t>(pair.site));
        auto target = static_cast<size_t>(module.objectIndex(group.target));
        FoldLaunch launch;
        launch.object = &object;
        launch.pair = &pair;
        launch.group = &group;
        launch.same = target == type;
        launch.self = side(pool);
        launch.other = side(pools[target]);
        for (size_t f = 0; f < pool.folds.count(); ++f) {
            std::array<Buffer, 4> components{};
            for (int c = 0; c < pool.folds.type(f).width; ++c) components[static_cast<size_t>(c)] = pool.folds.column(f, static_cast<size_t>(c));
            launch.results.push_back(components);
        }
        launch.externs = externs.data();
        launch.externCount = externs.size();
        if (!backend.fold(launch)) foldOnHost(launch);
        ++stats.folds;
    }
}

// The rows a launch's fold columns are gathered from: an object's own below foldRows,
// else (created since the folds) the row of empty folds.
void State::foldRowsOf(size_t type, std::span<uint32_t> rows) const {
    const Pool& pool = pools[type];
    for (uint32_t& r : rows)
        if (r != kSkipRow && r >= pool.foldRows) r = static_cast<uint32_t>(pool.foldRows);
}

}  // namespace psys::rt::detail
