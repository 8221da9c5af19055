#include "rt/memory.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <limits>
#include <new>
#include <stdexcept>

#include <fmt/format.h>

#include "rt/clock.h"
#include "rt/emission.h"

namespace psys::rt {

void Memory::clear(Buffer buffer, size_t first, size_t count) {
    if (count == 0) return;  // an empty column has no address
    std::memset(static_cast<char*>(host(buffer)) + first * elemSize(elem(buffer)), 0, count * elemSize(elem(buffer)));
}

void Memory::fill(Buffer buffer, size_t first, size_t count, uint32_t word) {
    if (count == 0) return;
    if (elemSize(elem(buffer)) != 4) throw std::logic_error("Memory::fill: a column of 4-byte elements");
    auto* words = static_cast<uint32_t*>(host(buffer)) + first;
    std::fill(words, words + count, word);
}

Bounds Memory::bounds(Buffer visible, const std::array<Buffer, 3>& position, const std::array<float, 3>& constant,
                      size_t rows) const {
    Bounds out;
    if (rows == 0) return out;
    const auto* shown = static_cast<const float*>(view(visible));
    for (int c = 0; c < 3; ++c) {
        const auto* x = position[static_cast<size_t>(c)].valid() ? static_cast<const float*>(view(position[static_cast<size_t>(c)])) : nullptr;
        float low = std::numeric_limits<float>::infinity(), high = -low;
        for (size_t r = 0; r < rows; ++r) {
            if (shown[r] != 1.0f) continue;
            float v = x ? x[r] : constant[static_cast<size_t>(c)];
            low = std::min(low, v);
            high = std::max(high, v);
        }
        out.low[static_cast<size_t>(c)] = low;
        out.high[static_cast<size_t>(c)] = high;
        out.empty = low > high;
    }
    return out;
}

// The bookkeeping of a pool's rows kept in a memory (Memory::allocateRows): the rules of
// rt/allocation.h over the buffers where the host addresses them.
void Memory::allocateRows(const PoolRows& pool, size_t top, size_t highWater, size_t n, Buffer out, size_t outFirst) {
    if (n == 0) return;
    const FreeRows free{static_cast<const uint32_t*>(view(pool.stack)), top, highWater, 0};
    auto* rows = static_cast<uint32_t*>(host(out)) + outFirst;
    for (size_t k = 0; k < n; ++k) rows[k] = free.row(k);
    auto* updatable = static_cast<uint8_t*>(host(pool.updatable));
    auto* alive = static_cast<uint8_t*>(host(pool.alive));
    for (size_t k = 0; k < n; ++k) {
        updatable[rows[k]] = 0;
        alive[rows[k]] = 1;
    }
    static_cast<uint32_t*>(host(pool.counters))[0] = static_cast<uint32_t>(top - std::min(n, top));
}

namespace {

// The pool rows of a kill list (Memory::releaseRows), in order: `each(i, row)`.
template <class Each>
void eachKilled(const Memory& memory, Buffer killed, size_t killedAt, uint32_t base, Buffer map, size_t mapFirst,
                Each each) {
    const auto* list = static_cast<const uint32_t*>(memory.view(killed)) + killedAt;
    if (list[0] == 0) return;
    const auto* rows = map.valid() ? static_cast<const uint32_t*>(memory.view(map)) + mapFirst : nullptr;
    for (uint32_t i = 0; i < list[0]; ++i) each(i, rows ? rows[list[1 + i]] : base + list[1 + i]);
}

// A freed row of a pool with parents (PoolRows::parents): a reader less of its parent.
std::function<void(uint32_t)> readerGone(Memory& memory, const PoolRows& pool) {
    if (!pool.parents.valid()) return [](uint32_t) {};
    const auto* parent = static_cast<const uint32_t*>(memory.view(pool.parents));
    auto* readers = static_cast<uint32_t*>(memory.host(pool.parentReaders));
    return [parent, readers](uint32_t row) {
        if (parent[row] != kSkipRow) --readers[parent[row]];
    };
}

}  // namespace

std::vector<uint32_t> Memory::killedRows(Buffer killed, size_t killedAt, uint32_t base, Buffer map,
                                         size_t mapFirst) const {
    std::vector<uint32_t> rows;
    eachKilled(*this, killed, killedAt, base, map, mapFirst, [&](uint32_t, uint32_t row) { rows.push_back(row); });
    return rows;
}

void Memory::releaseRows(const PoolRows& pool, Buffer killed, size_t killedAt, uint32_t base, Buffer map,
                         size_t mapFirst) {
    uint32_t& top = static_cast<uint32_t*>(host(pool.counters))[0];
    auto* stack = static_cast<uint32_t*>(host(pool.stack));
    auto* generation = static_cast<uint32_t*>(host(pool.generation));
    auto* updatable = static_cast<uint8_t*>(host(pool.updatable));
    auto* alive = static_cast<uint8_t*>(host(pool.alive));
    uint32_t pushed = 0;
    eachKilled(*this, killed, killedAt, base, map, mapFirst, [&](uint32_t i, uint32_t row) {
        stack[top + i] = row;
        ++generation[row];
        updatable[row] = alive[row] = 0;
        pushed = i + 1;
    });
    top += pushed;
}

void Memory::clearRows(const PoolRows& pool, Buffer killed, size_t killedAt, uint32_t base, Buffer map,
                       size_t mapFirst) {
    auto* updatable = pool.updatable.valid() ? static_cast<uint8_t*>(host(pool.updatable)) : nullptr;
    auto* alive = static_cast<uint8_t*>(host(pool.alive));
    eachKilled(*this, killed, killedAt, base, map, mapFirst, [&](uint32_t, uint32_t row) {
        if (updatable) updatable[row] = 0;
        alive[row] = 0;
    });
}

void Memory::appendKills(Buffer killed, size_t killedAt, uint32_t base, Buffer map, size_t mapFirst, Buffer into) {
    auto* list = static_cast<uint32_t*>(host(into));
    eachKilled(*this, killed, killedAt, base, map, mapFirst, [&](uint32_t, uint32_t row) { list[1 + list[0]++] = row; });
}

void Memory::parentsFromRecords(Buffer runs, size_t firstRecord, size_t records, size_t stride, Buffer map,
                                size_t mapFirst, size_t objects, size_t kept, Buffer parents, size_t first,
                                Buffer readers) {
    if (objects == 0) return;
    const auto* record = static_cast<const uint32_t*>(view(runs)) + firstRecord * kRunWords;
    const auto* through = map.valid() ? static_cast<const uint32_t*>(view(map)) + mapFirst : nullptr;
    auto* out = static_cast<uint32_t*>(host(parents)) + first;
    auto* count = static_cast<uint32_t*>(host(readers));
    for (size_t u = 0; u < records; ++u) {
        const uint32_t* w = record + u * kRunWords;
        auto j = static_cast<uint32_t>(u / stride);
        uint32_t row = through ? through[j] : static_cast<uint32_t>(mapFirst + j);
        for (uint32_t k = 0; k < w[1]; ++k) {
            out[w[0] + k] = row;
            if (w[0] + k < kept) ++count[row];
        }
    }
}

void Memory::gatherThrough(Buffer from, Buffer to, size_t toFirst, Buffer rows, size_t rowsFirst, size_t count) {
    if (count == 0) return;
    const auto* list = static_cast<const uint32_t*>(view(rows)) + rowsFirst;
    gather(from, to, toFirst, std::span<const uint32_t>(list, count));
}

void Memory::ancestorRows(Buffer parents, Buffer to, size_t toFirst, Buffer rows, size_t rowsFirst, size_t count) {
    if (count == 0) return;
    const auto* list = static_cast<const uint32_t*>(view(rows)) + rowsFirst;
    const auto* up = static_cast<const uint32_t*>(view(parents));
    auto* out = static_cast<uint32_t*>(host(to)) + toFirst;
    for (size_t i = 0; i < count; ++i) out[i] = list[i] == kSkipRow ? kSkipRow : up[list[i]];
}

void Memory::gatherAlive(Buffer alive, Buffer to, size_t toFirst, Buffer rows, size_t rowsFirst, size_t count) {
    if (count == 0) return;
    const auto* list = static_cast<const uint32_t*>(view(rows)) + rowsFirst;
    const auto* a = static_cast<const uint8_t*>(view(alive));
    auto* out = static_cast<float*>(host(to)) + toFirst;
    for (size_t i = 0; i < count; ++i) out[i] = list[i] != kSkipRow && a[list[i]] ? 1.0f : 0.0f;
}

void Memory::gatherAge(Buffer created, Buffer frozenAt, Buffer alive, Buffer to, size_t toFirst, Buffer rows,
                       size_t rowsFirst, size_t count, double now, Buffer nowRows, size_t nowFirst) {
    if (count == 0) return;
    const auto* list = static_cast<const uint32_t*>(view(rows)) + rowsFirst;
    const auto* c = static_cast<const double*>(view(created));
    const auto* d = static_cast<const double*>(view(frozenAt));
    const auto* a = static_cast<const uint8_t*>(view(alive));
    const auto* at = nowRows.valid() ? static_cast<const double*>(view(nowRows)) + nowFirst : nullptr;
    auto* out = static_cast<float*>(host(to)) + toFirst;
    for (size_t i = 0; i < count; ++i) {
        uint32_t p = list[i];
        out[i] = p == kSkipRow ? 0.0f : ageAt(a[p] ? (at ? at[i] : now) : d[p], c[p]);
    }
}

void Memory::stampDeaths(Buffer killed, size_t killedAt, uint32_t base, Buffer map, size_t mapFirst, Buffer frozenAt,
                         double t1, double dt, Buffer created, Buffer nows, Buffer lengths, size_t clocksFirst) {
    auto* d = static_cast<double*>(host(frozenAt));
    const auto* c = created.valid() ? static_cast<const double*>(view(created)) : nullptr;
    const auto* list = static_cast<const uint32_t*>(view(killed)) + killedAt + 1;
    const auto* now = nows.valid() ? static_cast<const double*>(view(nows)) + clocksFirst + mapFirst : nullptr;
    const auto* length = nows.valid() ? static_cast<const double*>(view(lengths)) + clocksFirst + mapFirst : nullptr;
    eachKilled(*this, killed, killedAt, base, map, mapFirst, [&](uint32_t i, uint32_t row) {
        d[row] = now ? now[list[i]] - length[list[i]] : c ? t1 - (t1 - c[row]) : t1 - dt;
    });
}

void Memory::subStepClocks(Buffer created, Buffer mask, Buffer step, Buffer now, Buffer dt, Buffer length,
                           size_t first, size_t n, uint32_t k, uint32_t most, double t1, double limit) {
    const auto* from = static_cast<const double*>(view(created)) + first;
    const auto* kept = static_cast<const uint8_t*>(view(mask)) + first;
    auto* on = static_cast<uint8_t*>(host(step)) + first;
    auto* at = static_cast<double*>(host(now)) + first;
    auto* narrow = static_cast<float*>(host(dt)) + first;
    auto* wide = length.valid() ? static_cast<double*>(host(length)) + first : nullptr;
    for (size_t r = 0; r < n; ++r) {
        if (!(k == 1 ? kept[r] : on[r])) {
            on[r] = 0;
            continue;
        }
        double span = t1 - from[r];
        uint64_t capped = 0;
        uint32_t steps = subStepCount(span, limit, capped);
        if (steps > most) throw std::logic_error("a new object's first update takes more sub-steps than its batch's bound");
        on[r] = k <= steps;
        if (!on[r]) continue;
        at[r] = subStepEnd(t1, span, k, steps);
        narrow[r] = static_cast<float>(span / steps);
        if (wide) wide[r] = span / steps;
    }
}

void Memory::survivors(Buffer mask, Buffer killed, Buffer out, size_t first, size_t count) {
    if (count == 0) return;
    const auto* m = static_cast<const uint8_t*>(view(mask)) + first;
    const auto* k = static_cast<const uint8_t*>(view(killed)) + first;
    auto* o = static_cast<uint8_t*>(host(out)) + first;
    for (size_t i = 0; i < count; ++i) o[i] = m[i] && !k[i];
}

void Memory::readersGone(Buffer killed, size_t killedAt, uint32_t base, Buffer map, size_t mapFirst, Buffer parents,
                         Buffer readers) {
    const auto* parent = static_cast<const uint32_t*>(view(parents));
    auto* count = static_cast<uint32_t*>(host(readers));
    eachKilled(*this, killed, killedAt, base, map, mapFirst, [&](uint32_t, uint32_t row) {
        if (parent[row] != kSkipRow) --count[parent[row]];
    });
}

void Memory::releaseUnread(const PoolRows& pool, Buffer killed, size_t killedAt, uint32_t base, Buffer map,
                           size_t mapFirst) {
    auto* counters = static_cast<uint32_t*>(host(pool.counters));
    auto* stack = static_cast<uint32_t*>(host(pool.stack));
    auto* generation = static_cast<uint32_t*>(host(pool.generation));
    auto* updatable = static_cast<uint8_t*>(host(pool.updatable));
    auto* alive = static_cast<uint8_t*>(host(pool.alive));
    const auto* readers = static_cast<const uint32_t*>(view(pool.readers));
    auto* waiting = static_cast<uint8_t*>(host(pool.waiting));
    auto parentReaderGone = readerGone(*this, pool);
    eachKilled(*this, killed, killedAt, base, map, mapFirst, [&](uint32_t, uint32_t row) {
        updatable[row] = alive[row] = 0;
        if (readers[row] > 0) {
            waiting[row] = 1;
            ++counters[kCounterWaiting];
            return;
        }
        stack[counters[kCounterTop]++] = row;
        ++generation[row];
        parentReaderGone(row);
    });
}

void Memory::releaseWaiting(const PoolRows& pool, size_t rows) {
    auto* counters = static_cast<uint32_t*>(host(pool.counters));
    if (rows == 0 || counters[kCounterWaiting] == 0) return;
    auto* stack = static_cast<uint32_t*>(host(pool.stack));
    auto* generation = static_cast<uint32_t*>(host(pool.generation));
    const auto* readers = static_cast<const uint32_t*>(view(pool.readers));
    auto* waiting = static_cast<uint8_t*>(host(pool.waiting));
    auto parentReaderGone = readerGone(*this, pool);
    for (uint32_t row = 0; row < rows; ++row) {
        if (!waiting[row] || readers[row] > 0) continue;
        waiting[row] = 0;
        --counters[kCounterWaiting];
        stack[counters[kCounterTop]++] = row;
        ++generation[row];
        parentReaderGone(row);
    }
}

void Memory::markFresh(const PoolRows& pool, Buffer rows, size_t first, size_t count) {
    if (count == 0) return;
    const auto* list = static_cast<const uint32_t*>(view(rows)) + first;
    auto* updatable = static_cast<uint8_t*>(host(pool.updatable));
    const auto* alive = static_cast<const uint8_t*>(view(pool.alive));
    for (size_t i = 0; i < count; ++i) updatable[list[i]] = alive[list[i]];
}

void Memory::scatter(std::span<const std::pair<Buffer, Buffer>> columns, size_t fromFirst, Buffer rows,
                     size_t rowsFirst, size_t count) {
    if (count == 0) return;
    const auto* list = static_cast<const uint32_t*>(view(rows)) + rowsFirst;
    for (auto [from, to] : columns) scatter(from, fromFirst, to, std::span<const uint32_t>(list, count));
}

void Memory::identify(const ObjectRuns& runs, size_t n, size_t kept, Buffer created, Buffer ids, Buffer mask,
                      size_t first) {
    if (n == 0) return;
    auto* c = static_cast<double*>(host(created)) + first;
    auto* id = static_cast<uint32_t*>(host(ids)) + first;
    auto* m = static_cast<uint8_t*>(host(mask)) + first;
    for (size_t r = 0; r < n; ++r) m[r] = r < kept;
    for (size_t u = 0; u < runs.size(); ++u)
        for (uint32_t k = 0; k < runs.count[u]; ++k) {
            size_t r = runs.first[u] + k;
            c[r] = runs.time(u, k);
            id[r] = runs.id[u] + k;
        }
}

void Memory::identifyRecords(Buffer runs, size_t firstRecord, size_t records, size_t objects, Buffer created,
                             Buffer ids, size_t first) {
    if (objects == 0) return;
    const auto* record = static_cast<const uint32_t*>(view(runs)) + firstRecord * kRunWords;
    auto* c = static_cast<double*>(host(created)) + first;
    auto* id = static_cast<uint32_t*>(host(ids)) + first;
    for (size_t u = 0; u < records; ++u) {
        const uint32_t* w = record + u * kRunWords;
        double firstTime, spacing;
        std::memcpy(&firstTime, w + 4, 8);
        std::memcpy(&spacing, w + 6, 8);
        for (uint32_t k = 0; k < w[1]; ++k) {
            c[w[0] + k] = eventTime(firstTime, k, w[3], spacing);
            id[w[0] + k] = w[2] + k;
        }
    }
}

RecordLayout::RecordLayout(const RateSites& in) : first(in.sites.size()), stride(in.sites.size()) {
    const size_t n = in.rows, sites = in.sites.size();
    size_t next = 0;  // the first record of the next group
    for (size_t g = 0; g < sites; ++g) {
        if (in.sites[g].group != g) continue;
        size_t rank = 0;
        for (size_t s = g; s < sites; ++s)
            if (in.sites[s].group == g) first[s] = next + rank++;
        for (size_t s = g; s < sites; ++s)
            if (in.sites[s].group == g) stride[s] = rank;
        next += rank * n;
    }
}

// A window's rows: its runs buffer within the block, and each column's rows it reads
// from a block-aligned row at most 63 before its first (GlMemory binds them so: an
// offset of 64 rows is 256 or 512 bytes, the most any GL asks) within it too.
size_t Memory::emissionWindow(size_t sites) const {
    if (maxBlockBytes == SIZE_MAX || sites == 0) return SIZE_MAX;
    // (At most 2³¹ bytes: a shader's word indices are 32-bit.)
    const size_t block = std::min<size_t>(maxBlockBytes, size_t{1} << 31);
    const size_t words = block / 4, totals = runsWords(0, sites);
    const size_t byRuns = words > totals ? (words - totals) / (sites * kRunWords) : 0;
    const size_t byColumns = block / 8 > 63 ? block / 8 - 63 : 0;
    const size_t rows = std::min(byRuns, byColumns);
    if (rows == 0)
        throw std::runtime_error(fmt::format("a storage block of {} bytes holds no emitter's records at {} sites",
                                             maxBlockBytes, sites));
    return rows;
}

// The rate emissions (and bursts) of emitter rows (Memory::emitAtRate):
// rt/emission.h's rules row by row, each group's objects kept while its room lasts, the
// ids in row order; a window goes on from the totals of the one before it.
void Memory::emitAtRate(const RateSites& in, Buffer runs) {
    if (in.now.valid() != in.length.valid()) throw std::logic_error("rate sites with a row's end but not its length");
    const size_t n = in.rows, sites = in.sites.size();
    auto* record = static_cast<uint32_t*>(host(runs));
    uint32_t* total = record + runsTotalsAt(n, sites);
    const size_t totalWords = runsWords(0, sites);  // (the totals alone)
    if (in.carry.valid())
        read(in.carry, in.carryAt, totalWords, total);
    else
        std::fill(total, total + totalWords, 0u);
    if (n == 0) return;
    const size_t f = in.first;
    const auto* mask = static_cast<const uint8_t*>(view(in.mask)) + f;
    const auto* killed = in.killed.valid() ? static_cast<const uint8_t*>(view(in.killed)) + f : nullptr;
    const auto* created = in.created.valid() ? static_cast<const double*>(view(in.created)) + f : nullptr;
    const auto* now = in.now.valid() ? static_cast<const double*>(view(in.now)) + f : nullptr;
    const auto* length = in.length.valid() ? static_cast<const double*>(view(in.length)) + f : nullptr;
    const RecordLayout layout(in);
    struct Site {
        const float *rate, *count;
        double* accumulated;
        uint64_t asked = 0;       // objects it asked for so far (saturating)
        uint64_t groupAsked = 0;  // (its group's first site's:) objects the group asked for so far
        uint32_t kept = 0;        // objects it kept so far
    };
    std::vector<Site> site;
    for (const RateSites::Site& s : in.sites)
        site.push_back({s.rate.valid() ? static_cast<const float*>(view(s.rate)) + f : nullptr,
                        s.count.valid() ? static_cast<const float*>(view(s.count)) + f : nullptr,
                        s.accumulated.valid() ? static_cast<double*>(host(s.accumulated)) + f : nullptr});
    // What the windows before asked and kept (none before the first): the totals so far.
    std::vector<uint64_t> groupStart(sites, 0);  // a group's objects asked before this window
    for (size_t k = 0; k < sites; ++k) {
        const uint32_t* t = total + kTotalsSites + kTotalsPerSite * k;
        site[k].asked = t[1] | uint64_t{t[2]} << 32;
        addSaturating(site[in.sites[k].group].groupAsked, site[k].asked);
    }
    for (size_t k = 0; k < sites; ++k) groupStart[k] = site[k].groupAsked;
    std::vector<uint32_t> keptBefore(sites);
    for (size_t k = 0; k < sites; ++k) keptBefore[k] = total[kTotalsSites + kTotalsPerSite * k];
    uint64_t invalid = total[kTotalsInvalid], clamped = total[kTotalsClamped];
    const uint32_t idsBefore = total[kTotalsIds];
    uint32_t id = in.nextId + idsBefore;
    for (size_t r = 0; r < n; ++r)
        for (size_t k = 0; k < sites; ++k) {
            const RateSites::Site& s = in.sites[k];
            Site& d = site[k];
            RateEmission e;
            const float count = d.count ? d.count[r] : s.countValue;
            if (s.kind != RateSites::Site::Kind::Rate && mask[r]) {
                e = burst(count, s.kind == RateSites::Site::Kind::Burst ? (now ? now[r] : in.t1) : created[r]);
                invalid += e.invalid;
                clamped += e.clamped;
            } else if (s.kind == RateSites::Site::Kind::Rate && mask[r] && !(killed && killed[r])) {
                const double end = now ? now[r] : in.t1;
                const double dt = length ? length[r] : created ? in.t1 - created[r] : in.dt;
                e = rateEmission(in.fresh ? 0.0 : d.accumulated[r], d.rate ? d.rate[r] : s.rateValue, count, dt, end);
                d.accumulated[r] = e.accumulated;
                invalid += e.invalid;
                clamped += e.clamped;
            }
            uint64_t& asked = site[s.group].groupAsked;
            const uint32_t room = in.sites[s.group].room;
            uint64_t before = asked;
            addSaturating(asked, e.children);
            addSaturating(d.asked, e.children);
            auto place = static_cast<uint32_t>(std::min<uint64_t>(before, room));
            auto kept = static_cast<uint32_t>(std::min<uint64_t>(asked, room)) - place;
            uint32_t* w = record + layout.record(k, r) * kRunWords;
            w[0] = place - static_cast<uint32_t>(std::min<uint64_t>(groupStart[s.group], room));
            w[1] = kept;
            w[2] = id;
            w[3] = static_cast<uint32_t>(std::min<uint64_t>(e.perEvent, UINT32_MAX));
            std::memcpy(w + 4, &e.firstTime, 8);
            std::memcpy(w + 6, &e.spacing, 8);
            w[kRunSitePlace] = d.kept;
            d.kept += kept;
            id += kept;
        }
    total[kTotalsInvalid] = static_cast<uint32_t>(std::min<uint64_t>(invalid, UINT32_MAX));
    total[kTotalsClamped] = static_cast<uint32_t>(std::min<uint64_t>(clamped, UINT32_MAX));
    total[kTotalsIds] = id - in.nextId;
    for (size_t k = 0; k < sites; ++k) {
        uint32_t* t = total + kTotalsSites + kTotalsPerSite * k;
        t[0] = keptBefore[k] + site[k].kept;
        t[1] = static_cast<uint32_t>(site[k].asked);
        t[2] = static_cast<uint32_t>(site[k].asked >> 32);
    }
}

}  // namespace psys::rt
