// The deaths of a step, from the kill to the free stack (rt/ledger.h): one record of a
// step's deaths and its late kills, settled by one call.
#include "rt/ledger.h"

#include <algorithm>
#include <stdexcept>

#include "rt/system_state.h"
#include "rt/system_support.h"

namespace psys::rt::detail {

void Ledger::kill(size_t type, uint32_t row, double at) {
    if (s_.pools[type].status(row) != Status::Alive) return;  // (the deaths' rows distinct: Pool::releaseFrozen)
    ++s_.typeStats[type].killed;
    s_.pools[type].freeze(row, at);  // no longer alive; freed at the end of the step if nobody reads it
    dying_.push_back({type, row});
}

void Ledger::kill(size_t type, Pool::RowLists lists, std::span<const double> at) {
    const size_t total = Pool::rowCount(lists);
    if (total == 0) return;
    s_.typeStats[type].killed += total;
    s_.pools[type].freeze(lists, at);
    size_t next = dying_.size();
    dying_.resize(next + total);
    for (std::span<const uint32_t> rows : lists)  // (8 bytes a row, in order)
        for (uint32_t row : rows) dying_[next++] = {type, row};
}

void Ledger::record(LateKills::Part& part, const RowsResult& result, Buffer flags, size_t begin, size_t end) const {
    part.ticket = result.ticket;
    part.begin = begin;
    part.listed = result.killsListed;
    part.counted = false;
    part.rows.clear();
    if (result.ticket || result.killed == 0) return;
    // (A part's vector is taken again step after step, and the kills of a chunk vary from
    // step to step: it grows to twice what it needs at least, up to the launch's rows, so
    // that it grows a few times at most.)
    if (part.rows.capacity() < result.killed)
        part.rows.reserve(std::min(std::max(2 * result.killed, 2 * part.rows.capacity()), end - begin));
    if (result.killedRows.size() == result.killed)
        part.rows.assign(result.killedRows.begin(), result.killedRows.end());
    else
        listKilled(s_.view<uint8_t>(flags), begin, end, part.rows);
}

void Ledger::defer(LateKills late) {
    late.at = dying_.size();
    late_.push_back(std::move(late));
}

Ledger::Spares& Ledger::spares(size_t type) {
    if (spares_.size() <= type) spares_.resize(s_.types.size() > type ? s_.types.size() : type + 1);
    return spares_[type];
}

LateKills Ledger::fresh(size_t type, size_t parts) {
    LateKills l;
    Spares& spare = spares(type);
    if (!spare.lates.empty()) {
        l = std::move(spare.lates.back());
        spare.lates.pop_back();
    }
    std::vector<LateKills::Part> kept = std::move(l.parts);
    std::vector<uint32_t> poolRows = std::move(l.poolRows);
    std::vector<double> spans = std::move(l.spans);
    l = {};
    l.type = type;
    for (LateKills::Part& part : kept) part.reset();
    l.parts = std::move(kept);
    l.poolRows = std::move(poolRows);
    l.poolRows.clear();
    l.spans = std::move(spans);
    l.spans.clear();
    resizeParts(l, parts);
    return l;
}

void Ledger::resizeParts(LateKills& l, size_t parts) {
    std::vector<std::vector<uint32_t>>& rows = spares(l.type).rows;
    for (; l.parts.size() > parts; l.parts.pop_back()) rows.push_back(std::move(l.parts.back().rows));
    while (l.parts.size() < parts) {
        LateKills::Part& part = l.parts.emplace_back();
        if (rows.empty()) continue;
        part.rows = std::move(rows.back());
        part.rows.clear();
        rows.pop_back();
    }
}

void Ledger::recycle(std::vector<LateKills>& lates) {
    for (LateKills& l : lates) {
        // (A husk whose vectors were moved on — take keeps some, free takes one out — has
        // nothing to give; past kMostSpares a type's spares are more than a step takes.)
        bool husk = l.parts.capacity() == 0 && l.poolRows.capacity() == 0 && l.spans.capacity() == 0;
        std::vector<LateKills>& kept = spares(l.type).lates;
        if (!husk && kept.size() < kMostSpares) kept.push_back(std::move(l));
    }
    lates.clear();
}

void Ledger::reserve(size_t type, size_t parts, size_t rowsEach, size_t lates) {
    std::vector<LateKills> made;
    for (size_t i = 0; i < lates; ++i) {
        LateKills& l = made.emplace_back(fresh(type, parts));
        for (LateKills::Part& part : l.parts) part.rows.reserve(rowsEach);
    }
    recycle(made);
}

void Ledger::settle(Wait wait) {
    if (owed_ && (wait == Wait::Yes || owedReady())) {
        Owed o = std::move(*owed_);
        owed_.reset();
        free(o.dying, o.late);
    }
    // A backend that clears kills itself shows the dead as dead already: nothing needs
    // them taken before the next settle that waits.
    if (wait == Wait::Yes || !s_.backend.clearsKilled()) take(dying_, late_);
}

void Ledger::endStep() {
    releaseAllInMemory(late_);
    auto owes = [](const LateKills& l) {
        return std::any_of(l.parts.begin(), l.parts.end(), [](const LateKills::Part& p) { return p.ticket != 0; });
    };
    if (s_.backend.clearsKilled() && std::any_of(late_.begin(), late_.end(), owes)) {
        owed_ = Owed{std::move(dying_), std::move(late_)};
        dying_.clear();
        late_.clear();
        return;
    }
    free(dying_, late_);
}

RowsResult Ledger::collect(size_t type, LateKills::Part& part) {
    if (!part.ticket) {
        RowsResult held;
        held.killedRows = part.rows;
        held.killed = part.rows.size();
        return held;
    }
    RowsResult result = s_.backend.collect(part.ticket);
    part.ticket = 0;
    s_.typeStats[type].unstable += result.unstable;
    return result;
}

// Where a part's kill list points (Memory::releaseRows' base and map): launch row r is
// pool row part.begin + r, or a batch's map[part.begin − first + r].
std::pair<uint32_t, size_t> Ledger::listRows(const LateKills& l, const LateKills::Part& part) {
    if (l.map.valid()) return {0, part.begin - l.first};
    return {static_cast<uint32_t>(part.begin), 0};
}

void Ledger::listInMemory(LateKills& l, bool aliveOnly) {
    Pool& pool = s_.pools[l.type];
    PoolRows masks = pool.memoryRows();
    if (aliveOnly) masks.updatable = {};
    std::vector<uint32_t> list;
    for (LateKills::Part& part : l.parts) {
        if (!part.killList.valid() || part.listed) continue;
        std::span<const uint32_t> rows = collect(l.type, part).killedRows;
        list.assign(1, static_cast<uint32_t>(rows.size()));
        for (uint32_t row : rows) list.push_back(static_cast<uint32_t>(row - part.begin));
        s_.memory.write(part.killList, 0, list.size(), list.data());
        s_.typeStats[l.type].killed += rows.size();
        part.listed = part.counted = true;
        part.count = rows.size();
        if (!rows.empty() && !s_.backend.clearsKilled()) {
            auto [base, mapFirst] = listRows(l, part);
            s_.memory.clearRows(masks, part.killList, 0, base, l.map, mapFirst);
        }
    }
}

// (Only the alive mask: the update's mask still holds them for the emissions of their
// deaths, after; the release clears it. And their deaths' times, where children read
// their ages.)
void Ledger::listNow(LateKills& l, Buffer nows, Buffer lengths) {
    listInMemory(l, true);
    Pool& pool = s_.pools[l.type];
    if (!pool.frozenAt.valid()) return;
    for (const LateKills::Part& part : l.parts) {  // (the time of their last values: children read their age)
        if (!part.killList.valid() || (part.counted && part.count == 0)) continue;
        auto [base, mapFirst] = listRows(l, part);
        s_.memory.stampDeaths(part.killList, 0, base, l.map, mapFirst, pool.frozenAt, l.t1, l.dt,
                              l.map.valid() ? pool.created : Buffer{}, nows, lengths, l.first);
    }
}

// (Where the backend clears kills, the update cleared them in the alive mask; the
// updatable mask here, but a batch's, whose new rows are not updatable yet — and here
// too where they were listed in the alive mask alone, a type children read: listNow.)
void Ledger::takeOut(LateKills& l, Buffer into, Buffer batchMask) {
    listInMemory(l);
    LateKills::Part* gathered = nullptr;  // (deferGathered's)
    for (auto it = late_.rbegin(); !gathered && it != late_.rend(); ++it)
        if (it->type == l.type && it->parts.size() == 1 && it->parts[0].gathered && it->parts[0].killList == into)
            gathered = &it->parts[0];
    if (!gathered) throw std::logic_error("kills taken out with no list to gather them into");
    Pool& pool = s_.pools[l.type];
    PoolRows updatable, step;
    updatable.alive = pool.updatable.column;
    step.alive = batchMask;
    const bool aliveOnly = s_.backend.clearsKilled() || s_.types[l.type].read;
    for (LateKills::Part& part : l.parts) {
        if (!part.killList.valid()) continue;
        if (!(part.counted && part.count == 0)) {
            auto [base, mapFirst] = listRows(l, part);
            if (aliveOnly && !l.map.valid()) s_.memory.clearRows(updatable, part.killList, 0, base, {}, 0);
            if (batchMask.valid()) s_.memory.clearRows(step, part.killList, 0, static_cast<uint32_t>(part.begin), {}, 0);
            s_.memory.appendKills(part.killList, 0, base, l.map, mapFirst, into);
        }
        ++gathered->lists;
        pool.recycle(part.killList);  // (the next sub-step's, then)
        part.killList = {};
        part.taken = true;
    }
    if (l.map.valid()) pool.recycle(l.map);
    l.map = {};
}

void Ledger::deferGathered(size_t type, Buffer into) {
    s_.memory.fill(into, 0, 1, 0);
    LateKills l = fresh(type, 1);
    LateKills::Part& part = l.parts[0];
    part.killList = into;
    part.listed = part.counted = part.gathered = true;
    defer(std::move(l));
}

// By the rule of `release`: a type at a time, the most deeply nested first, each type's
// kill lists in their order, then its frozen rows whose readers all went.
void Ledger::releaseAllInMemory(std::vector<LateKills>& lates) {
    for (size_t type : s_.deepestFirst) {
        if (!s_.types[type].rowsInMemory) continue;
        for (LateKills& l : lates)
            if (l.type == type) releaseInMemory(l);
        s_.pools[type].releaseWaiting();
    }
}

// Its kills freed where they are: a child's each a reader less of its parent, a parent's
// where nobody reads it (the others frozen: Pool::releaseUnread, counted from the memory;
// a row it frees a reader less of its own parent, where it has one).
void Ledger::releaseInMemory(LateKills& l) {
    if (l.released) return;
    listInMemory(l);
    l.released = true;
    Pool& pool = s_.pools[l.type];
    const bool read = pool.memoryRows().readers.valid();
    for (LateKills::Part& part : l.parts) {
        if (part.taken) {  // (freed with the step's gathered list: counted here where the host listed it)
            if (part.counted && !read) pool.released(part.count);
            continue;
        }
        if (!part.killList.valid()) continue;
        bool none = part.counted && part.count == 0 && !part.gathered;  // listed here, nothing to free
        if (!none) {
            auto [base, mapFirst] = listRows(l, part);
            if (read)
                pool.releaseUnread(part.killList, 0, base, l.map, mapFirst);
            else
                pool.release(part.killList, 0, base, l.map, mapFirst, part.gathered ? part.lists : 1);
            if (pool.parentRows.valid() && !read)  // (a read one's: as it frees them, PoolRows::parents)
                s_.memory.readersGone(part.killList, 0, base, l.map, mapFirst, pool.parentRows,
                                      s_.pools[static_cast<size_t>(s_.types[l.type].parentType)].memoryRows().readers);
            if (part.counted && !read && !part.gathered) pool.released(part.count);
        }
        pool.recycle(part.killList);
        part.killList = {};
    }
    if (l.map.valid()) pool.recycle(l.map);  // (its batch's rows: Pool::holdRows)
    l.map = {};
}

// A type at a time, the most deeply nested first (`release`'s order): its kill lists, then
// its frozen rows whose readers went — before its parent's turn, whose readers they count.
void Ledger::releaseForReload() {
    for (size_t type : s_.deepestFirst) {
        for (LateKills& l : late_)
            if (l.type == type) releaseForReload(l);
        s_.pools[type].releaseWaiting();
    }
    countParents();
}

void Ledger::releaseForReload(LateKills& l) {
    if (!s_.types[l.type].rowsInMemory || l.released) return;
    l.released = true;
    Pool& pool = s_.pools[l.type];
    std::vector<uint32_t> rows, list;
    for (LateKills::Part& part : l.parts) {
        if (!part.killList.valid()) continue;
        if (part.ticket) collect(l.type, part);  // (its unstable count: the kills are listed in the memory)
        list = l.map.valid() ? s_.memory.killedRows(part.killList, 0, 0, l.map, part.begin - l.first)
                             : s_.memory.killedRows(part.killList, 0, static_cast<uint32_t>(part.begin), {}, 0);
        rows.insert(rows.end(), list.begin(), list.end());
        if (!part.counted) s_.typeStats[l.type].killed += list.size();
        part.counted = true;
        pool.recycle(part.killList);
        part.killList = {};
    }
    if (l.map.valid()) pool.recycle(l.map);
    l.map = {};
    if (rows.empty()) return;
    std::sort(rows.begin(), rows.end());
    Buffer sorted = pool.scratchRows(rows.size() + 1);
    list.assign(1, static_cast<uint32_t>(rows.size()));
    list.insert(list.end(), rows.begin(), rows.end());
    s_.memory.write(sorted, 0, list.size(), list.data());
    if (pool.memoryRows().readers.valid()) {
        pool.releaseUnread(sorted, 0, 0, {}, 0);
    } else {
        pool.release(sorted, 0, 0, {}, 0);
        pool.released(rows.size());
    }
    if (pool.parentRows.valid() && !pool.memoryRows().readers.valid())
        s_.memory.readersGone(sorted, 0, 0, {}, 0, pool.parentRows,
                              s_.pools[static_cast<size_t>(s_.types[l.type].parentType)].memoryRows().readers);
    pool.recycle(sorted);
}

void Ledger::countInMemory(LateKills& l) {
    Pool& pool = s_.pools[l.type];
    for (LateKills::Part& part : l.parts) {
        if (part.counted) continue;
        part.counted = true;
        // (No ticket: listed by the backend with nothing killed; its release counted as 0.)
        size_t killed = part.ticket ? collect(l.type, part).killed : 0;
        s_.typeStats[l.type].killed += killed;
        if (!pool.memoryRows().readers.valid()) pool.released(killed);  // (else: countParents)
    }
}

// The pools children read: how many rows a step's releases froze and freed, as the memory
// counted them (once they are all done: after the step's end).
void Ledger::countParents() {
    for (Pool& pool : s_.pools)
        if (pool.memoryRows().readers.valid()) pool.countFromMemory();
}

void Ledger::take(Deaths& dying, std::vector<LateKills>& late) {
    if (late.empty()) return;
    Deaths& merged = lists_.merged;
    merged.clear();
    size_t next = 0;
    std::vector<LateKills>& kept = lists_.keptLates;  // those of types whose rows are in the memory, not freed yet
    kept.clear();
    for (LateKills& l : late) {
        if (s_.types[l.type].rowsInMemory) {
            if (l.released) {
                countInMemory(l);
            } else {  // (outside a step: a trigger's) freed at the next step's end
                listInMemory(l);
                kept.push_back(std::move(l));
            }
            continue;
        }
        for (; next < l.at; ++next) merged.push_back(dying[next]);
        Pool& pool = s_.pools[l.type];
        for (LateKills::Part& part : l.parts) {
            for (uint32_t launchRow : collect(l.type, part).killedRows) {
                uint32_t row = launchRow;
                double at = l.t1 - l.dt;
                if (!l.poolRows.empty()) {
                    size_t r = launchRow - l.first;
                    row = l.poolRows[r];
                    at = l.t1 - l.spans[r];
                } else if (l.scaled) {  // (a pool update's launch: its rows are the pool's)
                    at = l.t1 - l.dt * s_.rowSpeed(l.type, row);
                }
                ++s_.typeStats[l.type].killed;
                pool.freeze(row, at);
                merged.push_back({l.type, row});
            }
        }
    }
    for (; next < dying.size(); ++next) merged.push_back(dying[next]);
    dying.swap(merged);  // (each keeps its vector for the next)
    recycle(late);  // (those kept were moved out: their husks are taken again by fresh)
    late.swap(kept);
}

void Ledger::free(Deaths& deaths, std::vector<LateKills>& lates) {
    auto simple = [&](const LateKills& l) { return !s_.types[l.type].read && s_.types[l.type].parentType < 0; };
    if (std::none_of(lates.begin(), lates.end(), simple)) {
        take(deaths, lates);
        release(deaths);
        countParents();
        return;
    }
    // In the merged order of take: the deaths before each late launch's place, then its
    // kills. A simple type's rows touch no other pool, and its pool's free stack gets them
    // in that order: each part goes as one run; the deaths of parents and children by the
    // rule of `release`, after.
    size_t next = 0;
    Deaths& kept = lists_.kept;
    kept.clear();
    std::vector<std::vector<uint32_t>>& own = lists_.own;
    own.resize(s_.types.size());
    auto releaseUpTo = [&](size_t at) {  // (each simple type's rows in their order: a list freed in pieces)
        for (auto& rows : own) rows.clear();
        for (; next < at; ++next) {
            auto [type, row] = deaths[next];
            const TypeInfo& info = s_.types[type];
            if (info.read || info.parentType >= 0)
                kept.push_back(deaths[next]);
            else
                own[type].push_back(row);
        }
        for (size_t type = 0; type < own.size(); ++type) {
            std::span<const uint32_t> rows = own[type];
            if (!rows.empty()) s_.pools[type].releaseFrozen(Pool::RowLists(&rows, 1));
        }
    };
    for (LateKills& l : lates) {
        if (s_.types[l.type].rowsInMemory) {  // freed in the memory at the step's end (endStep): counted
            countInMemory(l);
            continue;
        }
        releaseUpTo(l.at);
        if (!simple(l)) {  // its kills frozen in its place, as take would
            // A list of its own each time: take leaves the list it settles holding only what
            // it keeps (nothing here: the type's rows are not in the memory).
            Deaths& its = lists_.its;
            its.clear();
            std::vector<LateKills>& single = lists_.single;
            single.clear();
            single.push_back(std::move(l));
            single[0].at = 0;
            take(its, single);
            kept.insert(kept.end(), its.begin(), its.end());
            recycle(single);
            continue;
        }
        // Every part's list at once (Pool::releaseKilled in pieces on every thread): a
        // device's lists copied (a collect's rows live until the next), a batch's mapped
        // from its launch rows to its pool rows.
        std::vector<std::span<const uint32_t>>& lists = lists_.spans;
        lists.clear();
        std::vector<std::vector<uint32_t>>& copies = lists_.copies;
        if (copies.size() < l.parts.size()) copies.resize(l.parts.size());
        size_t copied = 0;
        for (LateKills::Part& part : l.parts) {
            bool held = !part.ticket;
            std::span<const uint32_t> listed = collect(l.type, part).killedRows;
            s_.typeStats[l.type].killed += listed.size();
            if (l.poolRows.empty() && held) {
                lists.push_back(listed);
                continue;
            }
            std::vector<uint32_t>& rows = copies[copied++];
            rows.assign(listed.begin(), listed.end());
            if (!l.poolRows.empty())
                for (uint32_t& row : rows) row = l.poolRows[row - l.first];
            lists.push_back(rows);
        }
        s_.pools[l.type].releaseKilled(lists);
    }
    releaseUpTo(deaths.size());
    release(kept);
    deaths.clear();
    recycle(lates);
    countParents();
}

// The rule that frees rows (docs/architecture.md, "The life of a step"): a type at a time,
// the most deeply nested types first, so that a parent's readers are counted down before
// its turn — first its deaths, in the order they came, where nobody reads them; then its
// objects that died before and whose last reader went now, in row order. A freed object
// is a reader gone for its parent. Nothing depends on how one type's deaths interleave
// with its children's, so that a device freeing a kill list at a time, a type at a time,
// gives the same stacks.
void Ledger::release(Deaths& deaths) {
    if (deaths.empty()) return;
    const size_t types = s_.types.size();
    std::vector<std::vector<uint32_t>>&own = lists_.own, &waited = lists_.waited;
    own.resize(types);
    waited.resize(types);
    for (size_t type = 0; type < types; ++type) {
        own[type].clear();
        waited[type].clear();
    }
    for (auto [type, row] : deaths) own[type].push_back(row);
    auto free = [&](size_t type, uint32_t row) {
        Pool& pool = s_.pools[type];
        if (pool.status(row) != Status::Frozen || pool.readers[row] > 0) return;
        Handle parent = pool.parent[row];
        pool.release(row);
        int up = s_.types[type].parentType;
        if (up < 0 || !parent.valid()) return;
        Pool& parents = s_.pools[static_cast<size_t>(up)];
        if (!parents.matches(parent)) return;
        --parents.readers[parent.row];
        waited[static_cast<size_t>(up)].push_back(parent.row);
    };
    for (size_t type : s_.deepestFirst) {
        if (!s_.types[type].read && s_.types[type].parentType < 0) {  // (rows of its own: on every thread)
            std::span<const uint32_t> rows = own[type];
            s_.pools[type].releaseFrozen(Pool::RowLists(&rows, 1));
            continue;
        }
        for (uint32_t row : own[type]) free(type, row);
        std::vector<uint32_t>& rows = waited[type];
        std::sort(rows.begin(), rows.end());
        rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
        for (uint32_t row : rows) free(type, row);
    }
    deaths.clear();
}

void Ledger::freeUnread() {
    Deaths frozen;
    for (size_t t = 0; t < s_.pools.size(); ++t)
        for (uint32_t r = 0; r < s_.pools[t].rows(); ++r)
            if (s_.pools[t].status(r) == Status::Frozen) frozen.push_back({t, r});
    release(frozen);
}

bool Ledger::owedReady() {
    if (!owed_) return true;
    for (const LateKills& l : owed_->late)
        for (const LateKills::Part& p : l.parts)
            if (p.ticket && !s_.backend.ready(p.ticket)) return false;
    return true;
}

}  // namespace psys::rt::detail
