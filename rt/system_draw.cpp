#include "rt/system_draw.h"

#include <cmath>
#include <mutex>

#include "rt/system_support.h"

namespace psys::rt::detail {

Drawing::Drawing(State& state) : s_(state) {
    for (size_t t = 0; t < s_.pools.size(); ++t) types_.emplace_back(s_.memory);
}

void Drawing::invalidate() {
    for (Type& t : types_) t.stale = true;
}

const DrawColumns& Drawing::draw(size_t type) {
    Type& d = types_[type];
    if (!d.stale) return d.columns;
    d.stale = false;
    auto start = WallClock::now();
    const Pool& pool = s_.pools[type];
    const TypeInfo& info = s_.types[type];
    size_t rows = pool.rows();
    DrawColumns& out = d.columns;
    out = {};
    out.rows = rows;
    out.ids = pool.ids;
    if (!info.render || !info.drawn[0] || rows == 0) {
        out.rows = 0;
        return out;
    }
    const ColumnLayout& layout = info.renderLayout;
    s_.bindPool(type, layout, d.scratch, d.table);
    // A render value that is a state value is drawn from the state column itself.
    auto column = [&](int offset) { return d.table[static_cast<size_t>(layout.drawnFrom(offset))]; };
    out.visible = column(ColumnLayout::kVisible);
    for (int c = 0; c < 3; ++c) out.position[c] = column(ColumnLayout::kPosition + c);
    for (int c = 0; c < 4; ++c) out.color[c] = column(ColumnLayout::kColor + c);
    out.size = column(ColumnLayout::kSize);
    for (int c = 0; c < 8; ++c)
        if (auto k = layout.constant(ColumnLayout::kPosition + c)) out.constant[static_cast<size_t>(c)] = *k;
    // The rows drawn are among the alive ones: the pool keeps that mask (synced by bindPool).
    RowsLaunch launch;
    launch.object = &pool.object();
    launch.kernel = info.render;
    launch.layout = &layout;
    launch.columns = d.table;
    launch.mask = pool.alive.column;
    launch.clock = {Clock::Source::Uniform, Clock::Source::Uniform, s_.now, static_cast<float>(s_.lastDt), false};
    launch.externs = s_.externs.data();
    launch.uniforms = s_.uniforms(type, *info.render, static_cast<float>(s_.lastDt), static_cast<float>(s_.now));
    launch.seed = s_.options.seed;
    launch.draw = static_cast<uint32_t>(s_.step);
    const uint8_t* mask = pool.alive.host();
    // The rows drawn: marked by the render launch itself on a backend that does so (its
    // render columns stay where it computed them), else here.
    const bool marked = s_.backend.marksDrawn();
    float* visible = marked ? nullptr : s_.host<float>(out.visible);
    const float* values[8] = {};
    bool constantsFinite = true;  // the constant components: the same for every row
    if (!marked)
        for (int c = 0; c < 8; ++c) {
            if (auto k = layout.constant(ColumnLayout::kPosition + c)) constantsFinite &= std::isfinite(*k);
            else values[c] = s_.view<float>(column(ColumnLayout::kPosition + c));
        }
    std::mutex counting;
    size_t drawn = 0;
    uint64_t nonFinite = 0;
    s_.forChunks(rows, [&](size_t c) {
        RowsLaunch part = launch;
        part.begin = c * kRowsPerChunk;
        part.end = std::min(rows, part.begin + kRowsPerChunk);
        s_.gatherParents(type, layout, d.table, mask, part.begin, part.end, s_.now);
        RowsResult result = s_.backend.run(part);
        size_t chunkDrawn = result.drawn;
        uint64_t chunkNonFinite = result.nonFinite;
        // Drawn: alive, visible, and position, colour and size all finite.
        for (size_t row = part.begin; !marked && row < part.end; ++row) {
            if (!mask[row] || visible[row] == 0) {
                visible[row] = 0;
                continue;
            }
            bool finite = constantsFinite;
            for (const float* v : values)
                if (v) finite &= std::isfinite(v[row]);
            visible[row] = finite ? 1.0f : 0.0f;
            chunkDrawn += finite;
            chunkNonFinite += !finite;
        }
        std::lock_guard lock(counting);
        drawn += chunkDrawn;
        nonFinite += chunkNonFinite;
    });
    out.drawn = drawn;
    s_.stats.nonFiniteRender += nonFinite;
    s_.stats.drawSeconds += seconds(start, WallClock::now());
    return out;
}

std::vector<RenderPoint> Drawing::points(size_t type) {
    const DrawColumns& c = draw(type);
    std::vector<RenderPoint> out;
    if (c.rows == 0 || c.drawn == 0) return out;
    out.reserve(c.drawn);
    std::vector<float> visible(c.rows), values[8];
    std::vector<uint32_t> ids(c.rows);
    const Memory& memory = s_.memory;
    memory.read(c.visible, 0, c.rows, visible.data());
    memory.read(c.ids, 0, c.rows, ids.data());
    Buffer columns[8] = {c.position[0], c.position[1], c.position[2], c.color[0], c.color[1], c.color[2], c.color[3], c.size};
    for (int k = 0; k < 8; ++k) {
        if (!columns[k].valid()) {  // a constant
            values[k].assign(c.rows, c.constant[static_cast<size_t>(k)]);
            continue;
        }
        values[k].resize(c.rows);
        memory.read(columns[k], 0, c.rows, values[k].data());
    }
    for (size_t row = 0; row < c.rows; ++row) {
        if (visible[row] == 0) continue;
        out.push_back({ids[row],
                       {values[0][row], values[1][row], values[2][row]},
                       {values[3][row], values[4][row], values[5][row], values[6][row]},
                       values[7][row]});
    }
    return out;
}

}  // namespace psys::rt::detail
