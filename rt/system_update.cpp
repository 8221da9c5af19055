// Updating: the phases of a step over a type's pool (rt/schedule.h) — the update pass as
// launches over chunks, then its kills and its emissions in row order.
#include "rt/system_update.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <optional>

#include "rt/system_draw.h"
#include "rt/system_support.h"

namespace psys::rt::detail {

namespace {

// An earlier sub-step's late kills `l` of `type`, in the memory, taken out of its masks at
// once (the next sub-step must not update them), gathered into the step's list.
void takeOutKills(State& s, size_t type, LateKills& l) {
    TypeWork& work = s.work[type];
    if (!work.taken.valid()) {
        work.taken = s.pools[type].scratchRows(s.pools[type].rows() + 1);
        s.ledger.deferGathered(type, work.taken);
    }
    s.ledger.takeOut(l, work.taken);
}

}  // namespace

// After an update of `type`: the survivors emit, and the objects it killed their bursts
// on events (ir::EmitSite::whenKilled), in row order (their spawn launches run together at
// the end; a killed object's row keeps its last values until the step's end). A rate or count every
// row shares (ColumnLayout::sharedEmit) is taken from the externs or the launch's uniform
// values, not from its column: a device need not send it back.
void runEmissions(State& s, Creation& creation, size_t type, double dt, double t1) {
    const Pool& pool = s.pools[type];
    const TypeInfo& info = s.types[type];
    const TypeWork& work = s.work[type];
    if (!work.pass.ran) return;
    const ir::Object& o = pool.object();
    const Value* uniforms = s.uniforms(type, *info.update, static_cast<float>(dt), static_cast<float>(t1));
    if (info.rowsInMemory) {  // the memory decides them, where the rows are
        RateSites in;
        in.rows = pool.rows();
        in.mask = pool.updatable.column;
        if (info.kills) in.killed = work.updateTable[ColumnLayout::kKill];  // (in the memory: RowsLaunch::emissionsStay)
        in.dt = dt;
        std::vector<size_t> sites;  // (a burst at creation emits nothing here)
        for (size_t site = 0; site < o.emits.size(); ++site) {
            if (!o.emits[site].inUpdate()) continue;
            RateSites::Site& out = in.sites.emplace_back();
            out.kind = o.emits[site].rate() ? RateSites::Site::Kind::Rate : RateSites::Site::Kind::Burst;
            if (o.emits[site].rate()) out.accumulated = pool.emitted[site];
            sites.push_back(site);
        }
        s.gatherSpawnParents(type, sites, t1);  // (what its spawn kernels read of its parent, at t1)
        creation.emitInMemory(type, work.updateTable, &uniforms, std::move(in), sites, nullptr, {}, t1);
        creation.runSpawns();
        if (s.work[type].pass.untaken) {
            LateKills& l = *s.work[type].pass.untaken;
            takeOutKills(s, type, l);
            s.ledger.defer(std::move(l));
            s.work[type].pass.untaken.reset();
        }
        return;
    }
    const uint8_t* updatable = pool.mask();
    // (Every vector below is the type's, kept from step to step: a step allocates nothing.)
    EmissionWork& w = s.work[type].emission;
    const size_t sites = o.emits.size();
    w.rate.assign(sites, 0);
    w.count.assign(sites, 1);
    w.rates.assign(sites, nullptr);
    w.counts.assign(sites, nullptr);
    const ColumnLayout& layout = info.updateLayout;
    auto source = [&](bool yielded, int column, float& shared, const float*& perRow) {
        if (!yielded) return;
        if (auto v = layout.sharedEmit(column, s.externs.data(), uniforms))
            shared = *v;
        else
            perRow = s.view<float>(work.updateTable[static_cast<size_t>(column)]);
    };
    for (size_t site = 0; site < sites; ++site) {
        auto i = static_cast<int>(site);
        source(info.rated[site], layout.emitRate(i), w.rate[site], w.rates[site]);
        source(info.counted[site], layout.emitCount(i), w.count[site], w.counts[site]);
    }
    // Each row's emissions decided a piece of rows at a time on every thread (each moves
    // its own accumulators on), those that emit kept; then queued in row order: ids, rows
    // and the queue as one row at a time would give them.
    creation.accumulators(type, w.accumulated);
    const size_t pieces = (pool.rows() + kHostRows - 1) / kHostRows;
    if (w.pieces.size() < pieces) w.pieces.resize(pieces);
    const std::vector<uint32_t>& died = work.pass.dying;  // (in row order)
    s.forRows(0, pool.rows(), [&](size_t begin, size_t end) {
        EmissionWork::Piece& piece = w.pieces[begin / kHostRows];
        piece.rows.clear();
        piece.emissions.clear();
        piece.rate = w.rate;
        piece.count = w.count;
        piece.row.resize(sites);
        const State::RowSpeeds speedOf = s.rowSpeeds(type);
        auto dying = std::lower_bound(died.begin(), died.end(), begin);
        for (size_t row = begin; row < end; ++row) {
            bool dies = dying != died.end() && *dying == row;
            if (dies) ++dying;
            if (!updatable[row] && !dies) continue;
            for (size_t site = 0; site < sites; ++site) {
                if (w.rates[site]) piece.rate[site] = w.rates[site][row];
                if (w.counts[site]) piece.count[site] = w.counts[site][row];
            }
            const double own = s.scaledStep ? dt * speedOf(static_cast<uint32_t>(row)) : dt;  // (its instance's)
            Creation::emissionsOf(o, w.accumulated.data(), static_cast<uint32_t>(row), piece.rate, piece.count, own, t1,
                                  dies, piece.row.data());
            if (std::none_of(piece.row.begin(), piece.row.end(),
                             [](const RateEmission& x) { return x.children || x.invalid || x.clamped; }))
                continue;
            piece.rows.push_back(static_cast<uint32_t>(row));
            piece.emissions.insert(piece.emissions.end(), piece.row.begin(), piece.row.end());
        }
    });
    for (size_t p = 0; p < pieces; ++p) {
        const EmissionWork::Piece& piece = w.pieces[p];
        for (size_t i = 0; i < piece.rows.size(); ++i)
            creation.queueEmissions({type, piece.rows[i], {}, piece.rows[i], t1, false},
                                    std::span(piece.emissions).subspan(i * sites, sites));
    }
    creation.runSpawns();  // before the next sub-step's update moves the emitters on
}

// The kills of the update pass just run: listed per chunk (objects that only die) and
// taken now, or, for late launches, their kills (listed or ticketed) and unstable counts
// kept for the end of the step (or the next settle: rt/ledger.h), in their place
// (LateKills); else read from the kill flags in row order.
namespace {

// The times of the deaths in a type's kill lists: `at` (t1 − dt) for all, or in a scaled
// step each row's, t1 − its own dt (rt/system_speeds.cpp).
std::span<const double> killTimes(State& s, size_t type, double dt, double t1, const double& at) {
    if (!s.scaledStep) return {&at, 1};
    std::vector<double>& times = s.work[type].killTimes;  // (kept from step to step; System::reserve)
    times.clear();
    size_t killed = 0;
    for (std::span<const uint32_t> rows : s.work[type].killLists) killed += rows.size();
    if (times.capacity() < killed) times.reserve(2 * killed);  // (headroom: growing is rare)
    const State::RowSpeeds speedOf = s.rowSpeeds(type);
    for (std::span<const uint32_t> rows : s.work[type].killLists)
        for (uint32_t row : rows) times.push_back(t1 - dt * speedOf(row));
    if (times.empty()) return {&at, 1};
    return times;
}

}  // namespace

void runKills(State& s, size_t type, double dt, double t1) {
    TypeWork& work = s.work[type];
    const TypeInfo& info = s.types[type];
    if (!work.pass.ran) return;
    size_t chunks = work.pass.chunks;
    if (work.pass.late) {
        LateKills l = s.ledger.fresh(type, chunks);
        l.t1 = t1;
        l.dt = dt;
        l.scaled = s.scaledStep;
        for (size_t c = 0; c < chunks; ++c) std::swap(l.parts[c], work.killed[c]);  // (each keeps a vector)
        if (info.read && info.rowsInMemory) s.ledger.listNow(l);  // its dead are dead to its children at once
        if (work.pass.takeOut && info.updateEmits) {  // (after its emissions: takeOutKills)
            work.pass.untaken = std::move(l);
            return;
        }
        if (work.pass.takeOut) takeOutKills(s, type, l);
        s.ledger.defer(std::move(l));
        return;
    }
    if (work.pass.listed) {
        const double at = t1 - dt;
        work.killLists.clear();  // (taken at once: on every thread)
        for (size_t c = 0; c < chunks; ++c) work.killLists.push_back(work.killed[c].rows);
        s.ledger.kill(type, work.killLists, killTimes(s, type, dt, t1, at));
        return;
    }
    if (!info.kills) return;
    // The flags read a piece at a time on every thread, each piece's killed rows a list;
    // the lists taken as one, in row order.
    const Pool& pool = s.pools[type];
    const uint8_t* updatable = pool.mask();
    const auto* kill = s.view<uint8_t>(work.updateTable[ColumnLayout::kKill]);
    const size_t pieces = (pool.rows() + kHostRows - 1) / kHostRows;  // (the type's lists, kept from step to step)
    if (work.killPieces.size() < pieces) work.killPieces.resize(pieces);
    s.forRows(0, pool.rows(), [&](size_t begin, size_t end) {
        std::vector<uint32_t>& killed = work.killPieces[begin / kHostRows];
        killed.clear();
        for (size_t row = begin; row < end; ++row)
            if (updatable[row] && kill[row]) killed.push_back(static_cast<uint32_t>(row));
    });
    work.killLists.assign(work.killPieces.begin(), work.killPieces.begin() + static_cast<std::ptrdiff_t>(pieces));
    if (info.emitsWhenKilled)
        for (size_t p = 0; p < pieces; ++p)
            work.pass.dying.insert(work.pass.dying.end(), work.killPieces[p].begin(), work.killPieces[p].end());
    const double at = t1 - dt;
    s.ledger.kill(type, work.killLists, killTimes(s, type, dt, t1, at));
}

namespace {

// The update launch over `type`'s pool (its table bound) for (t1 − dt, t1], rows to be chosen.
RowsLaunch poolUpdate(State& s, size_t type, double dt, double t1) {
    const TypeInfo& info = s.types[type];
    TypeWork& work = s.work[type];
    s.bindPool(type, info.updateLayout, work.update, work.updateTable);
    RowsLaunch update;
    update.object = &s.pools[type].object();
    update.kernel = info.update;
    update.layout = &info.updateLayout;
    update.columns = work.updateTable;
    update.mask = s.pools[type].updatable.column;
    update.clock = {Clock::Source::Uniform, Clock::Source::Uniform, t1, static_cast<float>(dt), false};
    update.externs = s.externs.data();
    update.uniforms = s.uniforms(type, *info.update, static_cast<float>(dt), static_cast<float>(t1));
    update.seed = s.options.seed;
    update.draw = static_cast<uint32_t>(s.step);
    if (s.scaledStep) {  // each row's dt its instance's (rt/system_speeds.cpp), in a column past the scratch's others
        const ColumnLayout& l = info.updateLayout;
        work.updateTable[ColumnLayout::kDt] =
            work.update.at(static_cast<size_t>(1 + l.total - l.emits), Elem::F32, s.pools[type].rows(), s.pools[type].room());
        update.clock.dt = Clock::Source::PerRow;
        update.uniformKernel = s.uniformKernel(type, *info.update);
    }
    return update;
}

}  // namespace

// One update of every updatable object of `type` over (t1 − dt, t1]: the update kernel
// and the exports kernel over chunks of rows (on several threads where the backend
// allows), what each chunk killed listed by the chunk; the kills and emissions are the
// phases after it (runKills, runEmissions), in row order, so that ids, the queue and the
// free list come out the same with any number of threads.
void runUpdate(State& s, const Phase& phase, double dt, double t1, bool last) {
    auto type = static_cast<size_t>(phase.type);
    // Where nobody looks at its dead before the step's end (and this sub-step ends it), its
    // kills are taken then (LateKills); where its rows are in the memory, every sub-step's
    // kills are listed there, and an earlier sub-step's taken out of its masks at once
    // (runKills), freed at the step's end with the last's.
    const bool late = phase.late && (last || phase.inMemory);
    Pool& pool = s.pools[type];
    TypeInfo& info = s.types[type];
    TypeWork& work = s.work[type];
    std::vector<uint32_t> dying = std::move(work.pass.dying);
    work.pass = {};
    work.pass.dying = std::move(dying);
    work.pass.dying.clear();
    size_t rows = pool.rows();
    if (rows == 0) return;
    // Drawing as it goes (rt/system_draw.h): each chunk rendered after its update.
    std::optional<ChunkDrawing> drawing;
    if (last && work.inStep.on) drawing.emplace(s, type, t1);
    if (pool.liveAtMost() == 0) {  // nothing is drawn (what is created later is drawn at creation)
        if (drawing) drawing->none();
        return;
    }
    RowsLaunch update = poolUpdate(s, type, dt, t1);
    // (What the memory reads of the update stays there: its emissions, and the kill flags
    // of a type whose survivors' exports it computes.)
    update.emissionsStay = phase.inMemory && (info.updateEmits || (info.kills && info.exports));
    // (Where the rows are in the memory, nothing here reads the mask: its parents' rows
    // are there too, no drawing as the step goes, its folds copied, and its kills late —
    // its exports those of the survivors there.)
    const uint8_t* updatable = phase.inMemory ? nullptr : pool.mask();
    RowsLaunch exports = update;
    Buffer exportMask;
    if (info.exports) {
        s.bindPool(type, info.exportsLayout, work.exports, work.exportsTable);
        // Exports of the survivors: of a type that never dies, every row updated.
        exportMask = info.kills ? work.masks.at(0, Elem::U8, rows, pool.room()) : pool.updatable.column;
        exports.kernel = info.exports;
        exports.layout = &info.exportsLayout;
        exports.columns = work.exportsTable;
        exports.mask = exportMask;
        exports.uniforms = s.uniforms(type, *info.exports, static_cast<float>(dt), static_cast<float>(t1));
        if (s.scaledStep) {  // (the update's dt column)
            work.exportsTable[ColumnLayout::kDt] = work.updateTable[ColumnLayout::kDt];
            exports.uniformKernel = s.uniformKernel(type, *info.exports);
        }
    }
    // (Where the rows are in the memory the flags stay there: nothing here reads them.)
    const uint8_t* kill = phase.inMemory ? nullptr : s.view<uint8_t>(work.updateTable[ColumnLayout::kKill]);
    // Objects that only die (no rate emits) are found while their chunk is in cache
    // (Phase::listed); late, a device need not wait for them.
    const bool listKills = phase.listed;
    size_t chunks = s.chunkCount(rows);
    work.pass.ran = true;  // (dying, cleared above, keeps its vector)
    work.pass.late = late;
    work.pass.listed = listKills && !late;
    work.pass.takeOut = late && !last;
    work.pass.chunks = chunks;
    // Each chunk sets its own (Ledger::record); past `chunks`, parts kept for the rows the
    // pool may reach (System::reserve).
    if ((listKills || late) && work.killed.size() < chunks) work.killed.resize(chunks);
    if (late && phase.inMemory)
        for (size_t c = 0; c < chunks; ++c)
            work.killed[c].killList = pool.scratchRows(std::min(s.backend.chunkRows(), rows - c * s.backend.chunkRows()) + 1);
    std::atomic<uint64_t> unstable = 0;
    float* dts = s.scaledStep ? s.host<float>(work.updateTable[ColumnLayout::kDt]) : nullptr;
    auto chunk = [&](size_t c, size_t begin, size_t end) {
        if (dts) s.scaleRows(type, dt, dts, pool.mask(), begin, end);
        RowsLaunch part = update;
        part.begin = begin;
        part.end = end;
        part.late = late;
        if (late) part.aliveMask = pool.alive.column;  // its kills cleared there (Backend::clearsKilled)
        if (late && phase.inMemory)  // and listed, for the pool to free them where its rows are
            part.killList = work.killed[c].killList;
        s.gatherParents(type, info.updateLayout, work.updateTable, updatable, part.begin, part.end, t1);
        RowsResult result = s.backend.run(part);
        if (result.unstable) unstable += result.unstable;
        if (listKills || late) s.ledger.record(work.killed[c], result, work.updateTable[ColumnLayout::kKill], begin, end);
        if (info.exports) {
            const uint8_t* survivors = updatable;
            if (info.kills && phase.inMemory) {  // (where the flags are)
                s.memory.survivors(pool.updatable.column, work.updateTable[ColumnLayout::kKill], exportMask, part.begin,
                                   part.end - part.begin);
            } else if (info.kills) {
                auto* alive = s.host<uint8_t>(exportMask);
                maskRows(alive, updatable, kill, nullptr, part.begin, part.end);
                survivors = alive;
            }
            RowsLaunch post = exports;
            post.begin = part.begin;
            post.end = part.end;
            s.gatherParents(type, info.exportsLayout, work.exportsTable, survivors, post.begin, post.end, t1);
            s.backend.run(post);
        }
        if (drawing) drawing->chunk(updatable, info.kills ? kill : nullptr, part.begin, part.end);
    };
    s.forChunks(0, rows, chunk);
    s.typeStats[type].unstable += unstable;
    if (drawing) drawing->done();
}

}  // namespace psys::rt::detail
