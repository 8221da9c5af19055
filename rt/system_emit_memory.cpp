// The emissions the memory decides (Creation::emitInMemory): an emitter type's rate and
// burst sites over its rows as one operation of the memory (rt::Memory::emitAtRate), in
// windows of rows where the memory's largest buffer asks for them (emissionWindow); only
// the totals come back, and each group's objects are queued as runs and each site's spawn
// launches as launches from the records, where the records are (queueFromRecords).
#include "rt/system_create.h"

#include <algorithm>
#include <cstdint>

#include "rt/system_support.h"

namespace psys::rt::detail {

void Creation::emitInMemory(size_t type, const std::vector<Buffer>& table, const Value* const* uniforms,
                            RateSites in, std::span<const size_t> emitSite, const Batch* batch, Buffer rows, double t1) {
    using Kind = RateSites::Site::Kind;
    const TypeInfo& info = s_.types[type];
    const ColumnLayout& layout = info.updateLayout;
    const size_t n = in.rows, sites = in.sites.size();
    if (n == 0 || sites == 0) return;
    for (size_t k = 0; k < sites; ++k) {
        const size_t site = emitSite[k];
        auto i = static_cast<int>(site);
        RateSites::Site& out = in.sites[k];
        out.rateValue = 0;
        out.countValue = 1;
        // (A batch's clocks are its rows': its columns hold every rate and count.)
        auto source = [&](bool yielded, int column, float& shared, Buffer& perRow) {
            if (!yielded) return;
            if (auto v = uniforms ? layout.sharedEmit(column, s_.externs.data(), *uniforms) : std::nullopt)
                shared = *v;
            else
                perRow = table[static_cast<size_t>(column)];
        };
        if (out.kind == Kind::AtCreation) {  // init's count (Creation::queueBursts)
            out.count = batch->initTable[static_cast<size_t>(batch->initLayout.emitCount(i))];
        } else {
            if (out.kind == Kind::Rate) source(info.rated[site], layout.emitRate(i), out.rateValue, out.rate);
            source(info.counted[site], layout.emitCount(i), out.countValue, out.count);
        }
        size_t target = info.emitTarget[site];
        size_t group = 0;  // the first site into the same target
        while (info.emitTarget[emitSite[group]] != target) ++group;
        out.group = static_cast<uint32_t>(group);
        size_t free = s_.pools[target].free() + pending_[target];
        out.room = static_cast<uint32_t>(std::min<size_t>(free > queued_[target] ? free - queued_[target] : 0, UINT32_MAX));
    }
    in.t1 = t1;
    in.nextId = s_.nextId;
    // The records stay where they are; only the totals come back. More rows than a window
    // holds (a device's storage block) go as windows, each on from the one before.
    // (The queue refers to them until it is drained: a buffer a window.)
    const size_t window = s_.memory.emissionWindow(sites);
    std::vector<Window> windows;
    for (size_t at = 0; at < n; at += window) {
        RateSites part = in;
        part.rows = std::min(window, n - at);
        part.first = in.first + at;
        if (!windows.empty()) {
            part.carry = windows.back().runs;
            part.carryAt = runsTotalsAt(windows.back().rows, sites);
        }
        windows.push_back({runs_.at(runsUsed_++, Elem::U32, runsWords(part.rows, sites)), at, part.rows, {},
                           RecordLayout(part)});
        s_.memory.emitAtRate(part, windows.back().runs);
    }
    // Every window's totals in one read (one wait on a device): copied after one another
    // where there are several.
    const size_t words = runsWords(0, sites);
    std::vector<uint32_t> totals(words * windows.size());
    if (windows.size() == 1) {
        s_.memory.read(windows[0].runs, runsTotalsAt(windows[0].rows, sites), words, totals.data());
    } else {
        Buffer all = runs_.at(runsUsed_++, Elem::U32, totals.size());
        for (size_t u = 0; u < windows.size(); ++u)
            s_.memory.copy(windows[u].runs, runsTotalsAt(windows[u].rows, sites), all, u * words, words);
        s_.memory.read(all, 0, totals.size(), totals.data());
    }
    for (size_t u = 0; u < windows.size(); ++u)
        windows[u].total.assign(totals.begin() + static_cast<std::ptrdiff_t>(u * words),
                                totals.begin() + static_cast<std::ptrdiff_t>((u + 1) * words));
    const std::vector<uint32_t>& total = windows.back().total;
    s_.stats.invalidEmissions += total[kTotalsInvalid];
    s_.stats.clampedEmissions += total[kTotalsClamped];
    queueFromRecords(type, in, emitSite, batch, windows, rows, t1);
    s_.nextId += total[kTotalsIds];
}

// Each group's objects one run a window, and each site's emitters' spawn launches one
// launch a window, from the records (ChildrenLaunch::records): ids, times, places and
// emitter rows where the records are — a burst at creation's from the batch's state at
// creation, at each emitter's creation time. A window's places start at 0: its objects
// are staged after the earlier windows' (their kept, from the totals so far).
void Creation::queueFromRecords(size_t type, const RateSites& in, std::span<const size_t> emitSite, const Batch* batch,
                                const std::vector<Window>& windows, Buffer rows, double t1) {
    const TypeInfo& info = s_.types[type];
    const size_t sites = in.sites.size();
    const std::vector<uint32_t>& total = windows.back().total;
    auto groupKept = [&](const Window* w, size_t group) {  // its objects kept up to window w (0: none)
        uint64_t kept = 0;
        for (size_t k = group; w && k < sites; ++k)
            if (in.sites[k].group == group) kept += w->kept(k);
        return static_cast<size_t>(kept);
    };
    for (size_t group = 0; group < sites; ++group) {
        if (in.sites[group].group != group) continue;
        uint64_t asked = 0;
        for (size_t k = group; k < sites; ++k) {
            const uint32_t* t = total.data() + kTotalsSites + kTotalsPerSite * k;
            if (in.sites[k].group == group) addSaturating(asked, t[1] | uint64_t{t[2]} << 32);
        }
        const size_t kept = groupKept(&windows.back(), group);
        size_t target = info.emitTarget[emitSite[group]];
        addSaturating(s_.typeStats[target].dropped, asked - kept);
        if (kept == 0) continue;
        const size_t base = stage(target, kept);
        for (size_t u = 0; u < windows.size(); ++u) {
            const Window& w = windows[u];
            const Window* before = u ? &windows[u - 1] : nullptr;
            const size_t from = groupKept(before, group), its = groupKept(&w, group) - from;
            if (its == 0) continue;
            const RecordLayout& records = w.layout;
            queueSiteLaunches(type, in, emitSite, batch, w, before, group, base + from, its, rows, t1);
            enqueue({target, base + from, its, {}, 0, 0, 1, 0, w.runs, records.first[group], w.rows * records.stride[group],
                     records.stride[group], rows, w.at});
        }
    }
}

// Window w's spawn launches of a group's sites (its objects `its`, staged from `base`).
void Creation::queueSiteLaunches(size_t type, const RateSites& in, std::span<const size_t> emitSite,
                                 const Batch* batch, const Window& w, const Window* before, size_t group, size_t base,
                                 size_t its, Buffer rows, double t1) {
    using Kind = RateSites::Site::Kind;
    const RecordLayout& records = w.layout;
    for (size_t k = group; k < in.sites.size(); ++k) {
        if (in.sites[k].group != group) continue;
        const uint32_t siteKept = w.kept(k) - (before ? before->kept(k) : 0);
        if (siteKept == 0) continue;
        const bool atCreation = in.sites[k].kind == Kind::AtCreation;
        Emitter emitter{type, 0, {}, 0, t1, false};
        if (atCreation) emitter = {type, 0, batch->burstTables[emitSite[k]], 0, t1, true};
        // (A new emitter's sub-step whose arguments read an ancestor's age: its own table.)
        else if (batch && batch->inUpdateAged && !batch->agedTables[emitSite[k]].empty())
            emitter.columns = batch->agedTables[emitSite[k]];
        ChildrenLaunch* launch = queueSpawn(emitter, static_cast<int>(emitSite[k]), 0, siteKept, base, true);
        if (!launch) continue;
        launch->records = w.runs;
        launch->record = records.first[k];
        launch->recordCount = w.rows;
        launch->recordStride = records.stride[k];
        launch->placed = its;
        launch->rows = atCreation ? Buffer{} : rows;
        launch->rowsFirst = (atCreation ? batch->first : 0) + w.at;
        launch->nowFromRecords = atCreation;
        if (!atCreation && in.now.valid()) {  // (each emitter's sub-step end: the batch's column, which
                                              // holds it until the launch runs, before the next sub-step
                                              // or, after the last, at the next batch: firstUpdateInMemory)
            launch->nows = in.now;
            launch->nowsFirst = in.first + w.at;
        }
    }
}

}  // namespace psys::rt::detail
