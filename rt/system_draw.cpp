#include "rt/system_draw.h"

#include <array>
#include <cmath>
#include <cstring>
#include <mutex>
#include <span>

#include "core/few.h"
#include "rt/system_support.h"

namespace psys::rt {

static_assert(DrawColumns::kValues == ColumnLayout::kRenderColumns - ColumnLayout::kPosition &&
              ColumnLayout::kEnd + 3 == ColumnLayout::kRenderColumns);

void markDrawn(Memory& memory, const RowsLaunch& launch, const uint8_t* mask, size_t begin, size_t end,
               RowsResult& result) {
    const ColumnLayout& layout = *launch.layout;
    auto column = [&](int c) { return launch.columns[static_cast<size_t>(layout.drawnFrom(c))]; };
    float* visible = hostData<float>(memory, column(ColumnLayout::kVisible));
    // Every drawn value's column: position … a trail's last point (a trail's points are
    // columns past kRenderColumns; on the stack: a launch allocates nothing on whatever
    // thread runs it, core/few.h).
    core::Few<const float*, 64> columns(static_cast<size_t>(std::max(layout.renderColumns - ColumnLayout::kPosition, 0)));
    size_t count = 0;
    bool constantsFinite = true;       // the constant components: the same for every row
    for (int c = ColumnLayout::kPosition; c < layout.renderColumns; ++c) {
        if (auto k = layout.constant(c)) constantsFinite &= std::isfinite(*k);
        else columns[count++] = viewData<float>(memory, column(c));
    }
    const std::span<const float* const> values(columns.data(), count);
    for (size_t row = begin; row < end; ++row) {
        if (!mask[row] || visible[row] == 0) {
            visible[row] = 0;
            continue;
        }
        bool finite = constantsFinite;
        for (const float* v : values)
            if (v) finite &= std::isfinite(v[row]);
        visible[row] = finite ? 1.0f : 0.0f;
        result.drawn += finite;
        result.nonFinite += !finite;
    }
}

}  // namespace psys::rt

namespace psys::rt::detail {

RowsLaunch renderLaunch(State& s, size_t type, std::span<const Buffer> table, Buffer mask, double now) {
    const TypeInfo& info = s.types[type];
    RowsLaunch launch;
    launch.object = &s.pools[type].object();
    launch.kernel = info.render;
    launch.layout = &info.renderLayout;
    launch.columns = table;
    launch.mask = mask;
    launch.clock = {Clock::Source::Uniform, Clock::Source::Uniform, now, static_cast<float>(s.lastDt), false};
    launch.externs = s.externs.data();
    launch.uniforms = s.uniforms(type, *info.render, static_cast<float>(s.lastDt), static_cast<float>(now));
    launch.seed = s.options.seed;
    launch.draw = static_cast<uint32_t>(s.step);
    return launch;
}

DrawnCount renderRows(State& s, size_t type, const RowsLaunch& launch, const uint8_t* mask, size_t begin, size_t end,
                      const uint32_t* poolRows, size_t poolRowsFirst) {
    const ColumnLayout& layout = *launch.layout;
    RowsLaunch part = launch;
    part.begin = begin;
    part.end = end;
    s.gatherParents(type, layout, launch.columns, mask, begin, end, launch.clock.nowValue, nullptr, poolRows,
                    poolRowsFirst);
    RowsResult result = s.backend.run(part);
    DrawnCount count{result.drawn, result.nonFinite, result.ticket};
    if (s.backend.marksDrawn()) return count;  // its render columns stay where it computed them
    RowsResult marked;
    markDrawn(s.memory, part, mask, begin, end, marked);
    count.drawn += marked.drawn;
    count.nonFinite += marked.nonFinite;
    return count;
}

ChunkDrawing::ChunkDrawing(State& s, size_t type, double now) : s_(s), type_(type), rows_(s.pools[type].rows()) {
    TypeWork& work = s.work[type];
    s.bindPool(type, s.types[type].renderLayout, work.render, work.renderTable);
    Buffer mask = work.masks.at(1, Elem::U8, rows_, s.pools[type].room());  // (its capacity's room: it never moves)
    shown_ = s.host<uint8_t>(mask);
    alive_ = s.pools[type].alive.host();
    launch_ = renderLaunch(s, type, work.renderTable, mask, now);
}

void ChunkDrawing::chunk(const uint8_t* updatable, const uint8_t* kill, size_t begin, size_t end) {
    maskRows(shown_, alive_, kill ? updatable : nullptr, kill, begin, end);
    DrawnCount count = renderRows(s_, type_, launch_, shown_, begin, end);
    drawn_ += count.drawn;
    nonFinite_ += count.nonFinite;
}

void ChunkDrawing::none() {
    std::memset(shown_, 0, rows_);
    renderRows(s_, type_, launch_, shown_, 0, rows_);
}

void ChunkDrawing::done() {
    DrawnInStep& d = s_.work[type_].inStep;
    d.drawn += drawn_;
    d.nonFinite += nonFinite_;
}

Drawing::Drawing(State& state) : s_(state), types_(state.pools.size()) {}

void Drawing::invalidate(bool step) {
    for (Type& t : types_) t.stale = true;
    if (!step)
        for (TypeWork& w : s_.work) w.inStep.fresh = false;
}

// The render columns of `type`'s table as DrawColumns: a value that is a state value is
// drawn from the state column itself, a constant is handed over as its value.
void Drawing::hand(size_t type, DrawColumns& out) {
    const ColumnLayout& layout = s_.types[type].renderLayout;
    const std::vector<Buffer>& table = s_.work[type].renderTable;
    auto column = [&](int offset) { return table[static_cast<size_t>(layout.drawnFrom(offset))]; };
    out.visible = column(ColumnLayout::kVisible);
    for (int c = 0; c < 3; ++c) out.position[c] = column(ColumnLayout::kPosition + c);
    for (int c = 0; c < 4; ++c) out.color[c] = column(ColumnLayout::kColor + c);
    out.size = column(ColumnLayout::kSize);
    out.rotation = column(ColumnLayout::kRotation);
    out.frame = column(ColumnLayout::kFrame);
    for (int c = 0; c < 3; ++c) out.end[c] = column(ColumnLayout::kEnd + c);
    for (int c = 0; c < DrawColumns::kValues; ++c)
        if (auto k = layout.constant(ColumnLayout::kPosition + c)) out.constant[static_cast<size_t>(c)] = *k;
    for (int c = ColumnLayout::kTrail; c < layout.renderColumns; ++c) {
        auto k = layout.constant(c);
        out.trail.push_back(k ? Buffer{} : column(c));
        out.trailConstant.push_back(k.value_or(0.0f));
    }
}

void Drawing::takeCounts(size_t type) {
    Type& d = types_[type];
    for (uint64_t ticket : d.tickets) {
        RowsResult r = s_.backend.collect(ticket);
        d.columns.drawn += r.drawn;
        s_.stats.nonFiniteRender += r.nonFinite;
    }
    d.tickets.clear();
    d.columns.counted = true;
}

void Drawing::takeCounts() {
    for (size_t t = 0; t < types_.size(); ++t) takeCounts(t);
}

const DrawColumns& Drawing::draw(size_t type) {
    drew_ = true;
    Type& d = types_[type];
    if (!d.stale) return d.columns;
    takeCounts(type);
    d.stale = false;
    auto start = WallClock::now();
    const Pool& pool = s_.pools[type];
    const TypeInfo& info = s_.types[type];
    TypeWork& work = s_.work[type];
    size_t rows = pool.rows();
    DrawColumns& out = d.columns;
    out = {};
    out.rows = rows;
    out.ids = pool.ids;
    if (s_.module.instanced() && !pool.paramColumn.empty() && pool.paramColumn.back() >= 0)
        out.instance = pool.params.column(static_cast<size_t>(pool.paramColumn.back()), 0);
    if (!info.render || !info.drawn[0] || rows == 0) {
        out.rows = 0;
        return out;
    }
    s_.bindPool(type, info.renderLayout, work.render, work.renderTable);  // the alive mask synced too
    hand(type, out);
    if (work.inStep.fresh) {  // the step drew as it went: the columns are what is drawn
        out.drawn = work.inStep.drawn;
        s_.stats.nonFiniteRender += work.inStep.nonFinite;
        work.inStep.nonFinite = 0;
        s_.stats.drawSeconds += seconds(start, WallClock::now());
        return out;
    }
    // The rows drawn are among the alive ones, in parallel chunks. A device may answer
    // late: its counts are taken when they are asked for (takeCounts).
    RowsLaunch launch = renderLaunch(s_, type, work.renderTable, pool.alive.column, s_.now);
    launch.late = true;
    const uint8_t* mask = pool.alive.host();
    std::mutex counting;
    DrawnCount all;
    s_.forChunks(0, rows, [&](size_t, size_t begin, size_t end) {
        DrawnCount chunk = renderRows(s_, type, launch, mask, begin, end);
        std::lock_guard lock(counting);
        all.drawn += chunk.drawn;
        all.nonFinite += chunk.nonFinite;
        if (chunk.ticket) d.tickets.push_back(chunk.ticket);
    });
    out.drawn = all.drawn;
    out.counted = d.tickets.empty();
    s_.stats.nonFiniteRender += all.nonFinite;
    s_.stats.drawSeconds += seconds(start, WallClock::now());
    return out;
}

std::vector<RenderPoint> Drawing::points(size_t type) {
    const DrawColumns& c = draw(type);
    takeCounts(type);
    std::vector<RenderPoint> out;
    if (c.rows == 0 || c.drawn == 0) return out;
    out.reserve(c.drawn);
    std::vector<float> visible(c.rows), values[DrawColumns::kValues];
    std::vector<uint32_t> ids(c.rows);
    const Memory& memory = s_.memory;
    memory.read(c.visible, 0, c.rows, visible.data());
    memory.read(c.ids, 0, c.rows, ids.data());
    const std::array<Buffer, DrawColumns::kValues> columns = c.values();
    for (size_t k = 0; k < columns.size(); ++k) {
        if (!columns[k].valid()) {  // a constant
            values[k].assign(c.rows, c.constant[k]);
            continue;
        }
        values[k].resize(c.rows);
        memory.read(columns[k], 0, c.rows, values[k].data());
    }
    std::vector<std::vector<float>> trail(c.trail.size());
    for (size_t k = 0; k < c.trail.size(); ++k) {
        trail[k].assign(c.rows, c.trailConstant[k]);
        if (c.trail[k].valid()) memory.read(c.trail[k], 0, c.rows, trail[k].data());
    }
    for (size_t row = 0; row < c.rows; ++row) {
        if (visible[row] == 0) continue;
        out.push_back({ids[row],
                       {values[0][row], values[1][row], values[2][row]},
                       {values[3][row], values[4][row], values[5][row], values[6][row]},
                       values[7][row],
                       values[8][row],
                       values[9][row],
                       {values[10][row], values[11][row], values[12][row]},
                       {}});
        for (size_t k = 0; k + 2 < trail.size(); k += 3)
            out.back().trail.push_back({trail[k][row], trail[k + 1][row], trail[k + 2][row]});
    }
    return out;
}

}  // namespace psys::rt::detail
