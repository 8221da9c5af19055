// Rate emissions decided where the emitters' rows are (rt::Memory::emitAtRate): the GPU's
// dispatches (gpu/gl_emission.cpp) against the host's rule (rt/memory.cpp, rt/emission.h),
// record by record and bit by bit — the accumulators, each row's run, the totals — over
// rows that emit and rows that do not, rates and counts per row and shared, invalid and
// enormous values, targets that run out of room part-way, sites that share a target's
// room, and a batch's own clocks.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include <fmt/format.h>

#include "gpu/gl_memory.h"
#include "gpu_support.h"
#include "rt/emission.h"
#include "rt/memory.h"

using namespace psys;
using psys::test::gpuBackend;

namespace {

struct Emitters {
    rt::Memory& memory;
    rt::RateSites sites;
    rt::Buffer runs;  // the records, then the totals

    // The emitters are rows [first, first + rows) of their columns.
    Emitters(rt::Memory& m, size_t rows, size_t count, size_t first = 0) : memory(m) {
        sites.rows = rows;
        sites.first = first;
        sites.mask = m.create(rt::Elem::U8, first + rows);
        sites.killed = m.create(rt::Elem::U8, first + rows);
        sites.created = m.create(rt::Elem::F64, first + rows);
        for (size_t s = 0; s < count; ++s) {
            rt::RateSites::Site site;
            site.rate = m.create(rt::Elem::F32, first + rows);
            site.count = m.create(rt::Elem::F32, first + rows);
            site.accumulated = m.create(rt::Elem::F64, first + rows);
            site.group = static_cast<uint32_t>(s);  // (each into a target of its own)
            sites.sites.push_back(site);
        }
        runs = m.create(rt::Elem::U32, rt::runsWords(rows, count));
    }
    template <typename T>
    std::vector<T> read(rt::Buffer b, size_t n, size_t first = 0) const {
        std::vector<T> v(n);
        memory.read(b, first, n, v.data());
        return v;
    }
    // An emitter column's rows.
    template <typename T>
    void write(rt::Buffer b, const std::vector<T>& v) {
        memory.write(b, sites.first, v.size(), v.data());
    }
};

float oneOf(std::mt19937& random, std::initializer_list<float> values) {
    return *(values.begin() + random() % values.size());
}

}  // namespace

TEST_CASE("rate emissions decided on the GPU: the host's runs, ids, drops and accumulators, bit for bit") {
    // Sites at a rate and bursts on death, every round some of each; sites 1 and 3 into
    // one target (a group: its room shared, its objects placed in row order). The same
    // rows as windows too (RateSites::carry), on both memories.
    auto gpu = gpuBackend();
    rt::HostMemory hostMemory;
    constexpr size_t kRows = 3000, kSites = 4, kWindow = 700;
    Emitters host(hostMemory, kRows, kSites, 5), device(gpu->memory(), kRows, kSites, 5);
    Emitters hostWindows(hostMemory, kRows, kSites, 5), deviceWindows(gpu->memory(), kRows, kSites, 5);
    const std::initializer_list<Emitters*> all = {&host, &device, &hostWindows, &deviceWindows};
    for (Emitters* e : all) e->sites.sites[3].group = 1;
    for (Emitters* e : all) {  // (each row's sub-step: some rounds)
        e->sites.now = e->memory.create(rt::Elem::F64, 5 + kRows);
        e->sites.length = e->memory.create(rt::Elem::F64, 5 + kRows);
    }
    const rt::RecordLayout layout(host.sites);
    std::mt19937 random(11);
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    uint32_t nextId = 100;
    bool cut = false, clamped = false;
    for (int round = 0; round < 6; ++round) {
        INFO("round " << round);
        std::vector<uint8_t> mask(kRows), killed(kRows);
        std::vector<double> created(kRows), now(kRows), length(kRows);
        for (size_t r = 0; r < kRows; ++r) {
            mask[r] = random() % 5 != 0;
            killed[r] = random() % 9 == 0;
            created[r] = 1.0 + (random() % 1000) / 997.0 + round;  // before t1 = 2.5 + round
            // A sub-step of its first update: the k-th of 3, over a third of its span.
            double span = 2.5 + round - created[r];
            length[r] = span / 3;
            now[r] = created[r] + span * static_cast<double>(r % 3 + 1) / 3;
        }
        for (Emitters* e : all) {
            e->write(e->sites.mask, mask);
            e->write(e->sites.killed, killed);
            e->write(e->sites.created, created);
            e->write(e->sites.now, now);
            e->write(e->sites.length, length);
            e->sites.dt = round % 2 ? 1.0 / 60 : 1.0 / 7;
            e->sites.t1 = 2.5 + round;
            e->sites.nextId = nextId;
        }
        // Some rounds clock each row from its creation (a batch's first update), some over
        // each row's own sub-step (its end and length: RateSites::now, length).
        bool ownClock = round % 3 == 2, subStep = round % 3 == 1;
        uint32_t shared = 0;  // the group's room
        for (size_t s = 0; s < kSites; ++s) {
            std::vector<float> rate(kRows), count(kRows);
            for (size_t r = 0; r < kRows; ++r) {
                rate[r] = random() % 50 == 0 ? oneOf(random, {nan, inf, -1, 0, 1e30f, 0.25f})
                                             : static_cast<float>(random() % 4000) / 7.0f;
                count[r] = random() % 60 == 0 ? oneOf(random, {nan, -2, 0, 0.5f, 1e25f, 3.7f}) : 1 + random() % 4;
            }
            bool perRowRate = (round + s) % 4 != 0, perRowCount = (round + s) % 3 != 0;
            // Room: plenty, some, none — the last sites run out part-way (a group's is its
            // first site's).
            auto room = static_cast<uint32_t>(s == 0 ? 10'000'000 : s == 1 ? 20'000 + random() % 30'000 : random() % 50);
            if (s == 1) shared = room;
            if (s == 3) room = shared;
            for (Emitters* e : all) {
                rt::RateSites::Site& site = e->sites.sites[s];
                e->write(site.rate, rate);
                e->write(site.count, count);
                site.rateValue = perRowRate ? 0 : 240.5f;
                site.countValue = perRowCount ? 1 : 2;
                site.room = room;
            }
        }
        auto sitesOf = [&](Emitters& e) {
            rt::RateSites in = e.sites;
            if (!ownClock && !subStep) in.created = {};
            if (!subStep) in.now = in.length = {};
            in.fresh = (ownClock || subStep) && round % 2 == 0;
            for (size_t s = 0; s < kSites; ++s) {
                if ((round + s) % 4 == 0) in.sites[s].rate = {};
                if ((round + s) % 3 == 0) in.sites[s].count = {};
                // Bursts in an update (rows killed too; no accumulator), and at creation
                // (each row's creation time: where the round clocks rows from it).
                using Kind = rt::RateSites::Site::Kind;
                in.sites[s].kind = (round + s) % 5 == 1 ? Kind::Burst
                                   : (ownClock || subStep) && (round + s) % 5 == 3 ? Kind::AtCreation
                                                                     : Kind::Rate;
            }
            return in;
        };
        auto run = [&](Emitters& e) { e.memory.emitAtRate(sitesOf(e), e.runs); };
        run(host);
        run(device);
        // Windows of kWindow rows, each on from the one before: their runs, by window.
        auto windows = [&](Emitters& e) {
            std::vector<std::vector<uint32_t>> out;
            rt::Buffer before;
            for (size_t at = 0; at < kRows; at += kWindow) {
                rt::RateSites in = sitesOf(e);
                in.rows = std::min(kWindow, kRows - at);
                in.first += at;
                in.carry = before;
                in.carryAt = rt::runsTotalsAt(kWindow, kSites);
                rt::Buffer runs = e.memory.create(rt::Elem::U32, rt::runsWords(in.rows, kSites));
                e.memory.emitAtRate(in, runs);
                out.push_back(e.read<uint32_t>(runs, rt::runsWords(in.rows, kSites)));
                if (before.valid()) e.memory.release(before);
                before = runs;
            }
            e.memory.release(before);
            return out;
        };
        const std::vector<std::vector<uint32_t>> hostParts = windows(hostWindows), deviceParts = windows(deviceWindows);
        REQUIRE(hostParts == deviceParts);
        const size_t words = rt::runsTotalsAt(kRows, kSites), all = rt::runsWords(kRows, kSites);
        std::vector<uint32_t> runs = host.read<uint32_t>(host.runs, all);
        std::vector<uint32_t> deviceRuns = device.read<uint32_t>(device.runs, all);
        std::vector<uint32_t> totals(runs.begin() + static_cast<std::ptrdiff_t>(words), runs.end());
        REQUIRE(totals == std::vector<uint32_t>(deviceRuns.begin() + static_cast<std::ptrdiff_t>(words), deviceRuns.end()));
        auto differs = std::mismatch(runs.begin(), runs.end(), deviceRuns.begin());
        if (differs.first != runs.end()) {
            auto word = static_cast<size_t>(differs.first - runs.begin());
            INFO("record " << word / rt::kRunWords << ", word " << word % rt::kRunWords);
            REQUIRE(*differs.first == *differs.second);
        }
        for (size_t s = 0; s < kSites; ++s)
            for (Emitters* e : {&device, &hostWindows, &deviceWindows})
                REQUIRE(host.read<uint64_t>(host.sites.sites[s].accumulated, kRows, 5) ==
                        e->read<uint64_t>(e->sites.sites[s].accumulated, kRows, 5));
        // The windows' records are the whole operation's, their places counted from each
        // window's first record of the group (and of the site); the last one's totals the
        // whole's.
        REQUIRE(std::vector<uint32_t>(hostParts.back().end() - static_cast<std::ptrdiff_t>(totals.size()),
                                      hostParts.back().end()) == totals);
        for (size_t u = 0; u < hostParts.size(); ++u) {
            const size_t at = u * kWindow;
            rt::RateSites part = host.sites;
            part.rows = std::min(kWindow, kRows - at);
            const rt::RecordLayout its(part);
            for (size_t s = 0; s < kSites; ++s) {
                const uint32_t* start = runs.data() + layout.record(host.sites.sites[s].group, at) * rt::kRunWords;
                const uint32_t* own = runs.data() + layout.record(s, at) * rt::kRunWords;
                for (size_t r = at; r < std::min(at + kWindow, kRows); ++r) {
                    INFO("window " << u << ", site " << s << ", row " << r);
                    const uint32_t* whole = runs.data() + layout.record(s, r) * rt::kRunWords;
                    std::vector<uint32_t> want(whole, whole + rt::kRunWords);
                    want[0] -= start[0];
                    want[rt::kRunSitePlace] -= own[rt::kRunSitePlace];
                    const uint32_t* got = hostParts[u].data() + its.record(s, r - at) * rt::kRunWords;
                    REQUIRE(std::vector<uint32_t>(got, got + rt::kRunWords) == want);
                }
            }
        }
        for (size_t s = 0; s < kSites; ++s) {
            const uint32_t* t = totals.data() + rt::kTotalsSites + rt::kTotalsPerSite * s;
            uint64_t asked = t[1] | uint64_t{t[2]} << 32;
            cut = cut || asked > t[0];
        }
        // A group's sites take places among its objects in row order, a row's sites in
        // order, and each its own places among its own.
        uint32_t groupPlace = 0, sitePlace[kSites] = {};
        for (size_t r = 0; r < kRows; ++r)
            for (size_t s : {1, 3}) {
                const uint32_t* w = runs.data() + layout.record(s, r) * rt::kRunWords;
                REQUIRE(w[0] == groupPlace);
                REQUIRE(w[rt::kRunSitePlace] == sitePlace[s]);
                groupPlace += w[1];
                sitePlace[s] += w[1];
            }
        // Each group's objects' creation times and ids from its records where they are:
        // the same bits on both memories, and those of identify from the same runs as a list.
        for (size_t s = 0; s < kSites; ++s) {
            if (host.sites.sites[s].group != s) continue;
            uint32_t objects = 0;
            for (size_t k = s; k < kSites; ++k)
                if (host.sites.sites[k].group == s) objects += totals[rt::kTotalsSites + rt::kTotalsPerSite * k];
            const size_t records = kRows * layout.stride[s];
            rt::ObjectRuns list;
            for (size_t r = 0; r < records; ++r) {
                const uint32_t* w = runs.data() + (layout.first[s] + r) * rt::kRunWords;
                double firstTime, spacing;
                std::memcpy(&firstTime, w + 4, 8);
                std::memcpy(&spacing, w + 6, 8);
                list.first.push_back(w[0]);
                list.count.push_back(w[1]);
                list.id.push_back(w[2]);
                list.perEvent.push_back(w[3]);
                list.firstTime.push_back(firstTime);
                list.spacing.push_back(spacing);
            }
            std::vector<uint64_t> created[3];
            std::vector<uint32_t> ids[3];
            int which = 0;
            for (Emitters* e : {&host, &device, &host}) {
                rt::Buffer c = e->memory.create(rt::Elem::F64, objects + 3), i = e->memory.create(rt::Elem::U32, objects + 3),
                           m = e->memory.create(rt::Elem::U8, objects + 3);
                if (which < 2)
                    e->memory.identifyRecords(e->runs, layout.first[s], records, objects, c, i, 3);
                else
                    e->memory.identify(list, objects, objects, c, i, m, 3);
                created[which] = e->read<uint64_t>(c, objects, 3);
                ids[which] = e->read<uint32_t>(i, objects, 3);
                for (rt::Buffer b : {c, i, m}) e->memory.release(b);
                ++which;
            }
            CHECK(created[0] == created[1]);
            CHECK(created[0] == created[2]);
            CHECK(ids[0] == ids[1]);
            CHECK(ids[0] == ids[2]);
        }
        clamped = clamped || totals[rt::kTotalsClamped] > 0;
        CHECK(totals[rt::kTotalsInvalid] > 0);
        nextId += totals[rt::kTotalsIds];
    }
    CHECK(cut);
    CHECK(clamped);
    CHECK(nextId > 100'000);
}

TEST_CASE("a rate emission's records are the rule's: events, times, ids in row order and the cut at room") {
    // Two rows, two sites, on the host: the records say what rt::rateEmission says, the
    // ids run row by row, sites in order, and the second site's room of 5 cuts the
    // second row's ask.
    rt::HostMemory m;
    Emitters e(m, 2, 2);
    e.write(e.sites.mask, std::vector<uint8_t>{1, 1});
    e.write(e.sites.killed, std::vector<uint8_t>{0, 0});
    e.write(e.sites.sites[0].accumulated, std::vector<double>{0.5, 0});
    e.write(e.sites.sites[1].accumulated, std::vector<double>{0, 0.9});
    e.sites.created = {};
    e.sites.dt = 0.1;
    e.sites.t1 = 1;
    e.sites.nextId = 7;
    e.sites.sites[0].rate = {};
    e.sites.sites[0].rateValue = 30;  // 0.5 + 3: 3 events
    e.sites.sites[0].count = {};
    e.sites.sites[0].countValue = 2;
    e.sites.sites[0].room = 100;
    e.write(e.sites.sites[1].rate, std::vector<float>{40, 21});  // 4 events; 0.9 + 2.1: 3 events
    e.write(e.sites.sites[1].count, std::vector<float>{1, 1});
    e.sites.sites[1].room = 5;
    m.emitAtRate(e.sites, e.runs);
    auto runs = e.read<uint32_t>(e.runs, rt::runsWords(2, 2));
    auto record = [&](size_t site, size_t row) { return runs.data() + (site * 2 + row) * rt::kRunWords; };
    auto time = [](const uint32_t* w, size_t at) {
        double t;
        std::memcpy(&t, w + at, 8);
        return t;
    };
    rt::RateEmission first = rt::rateEmission(0.5, 30, 2, 0.1, 1);
    CHECK(first.children == 6);
    // Row 0: site 0 (6 objects, ids 7…12), site 1 (4: 13…16); row 1: site 0 (6: 17…22), site 1 (1 of 3: 23).
    CHECK(record(0, 0)[0] == 0);
    CHECK(record(0, 0)[1] == 6);
    CHECK(record(0, 0)[2] == 7);
    CHECK(record(0, 0)[3] == 2);
    CHECK(time(record(0, 0), 4) == first.firstTime);
    CHECK(time(record(0, 0), 6) == first.spacing);
    CHECK(record(1, 0)[1] == 4);
    CHECK(record(1, 0)[2] == 13);
    CHECK(record(0, 1)[0] == 6);
    CHECK(record(0, 1)[2] == 17);
    CHECK(record(1, 1)[0] == 4);
    CHECK(record(1, 1)[1] == 1);
    CHECK(record(1, 1)[2] == 23);
    const uint32_t* totals = runs.data() + rt::runsTotalsAt(2, 2);
    CHECK(totals[rt::kTotalsIds] == 17);
    CHECK(totals[rt::kTotalsSites + rt::kTotalsPerSite] == 5);       // site 1 kept
    CHECK(totals[rt::kTotalsSites + rt::kTotalsPerSite + 1] == 7);   // of 7 asked
    CHECK(e.read<double>(e.sites.sites[0].accumulated, 2)[0] == doctest::Approx(0.5));
    // A burst on death: `count` objects at t1 from each row of the mask, killed or not
    // (the update yields 0 where nothing died), its accumulator untouched.
    e.write(e.sites.killed, std::vector<uint8_t>{1, 0});
    e.sites.sites[1].kind = rt::RateSites::Site::Kind::Burst;
    e.write(e.sites.sites[1].count, std::vector<float>{3, 0});
    e.sites.sites[1].room = 100;
    m.emitAtRate(e.sites, e.runs);
    runs = e.read<uint32_t>(e.runs, rt::runsWords(2, 2));
    CHECK(record(1, 0)[1] == 3);
    CHECK(record(1, 0)[3] == 1);
    CHECK(time(record(1, 0), 4) == 1.0);
    CHECK(time(record(1, 0), 6) == 0.0);
    CHECK(record(1, 1)[1] == 0);
    CHECK(record(0, 0)[1] == 0);  // (the killed row emits at no rate)
    CHECK(e.read<double>(e.sites.sites[1].accumulated, 2)[1] == doctest::Approx(0.9 + 2.1 - 3));
    // A burst at creation: `count` objects at each row's creation time, killed or not.
    e.sites.sites[1].kind = rt::RateSites::Site::Kind::AtCreation;
    e.sites.created = m.create(rt::Elem::F64, 2);
    e.write(e.sites.created, std::vector<double>{0.25, 0.5});
    m.emitAtRate(e.sites, e.runs);
    runs = e.read<uint32_t>(e.runs, rt::runsWords(2, 2));
    CHECK(record(1, 0)[1] == 3);
    CHECK(time(record(1, 0), 4) == 0.25);
    CHECK(time(record(1, 0), 6) == 0.0);
    CHECK(record(1, 1)[1] == 0);
}

TEST_CASE("sites into one target share its room: places in row order, a row's sites in order, on both memories") {
    // Two rows, three sites: 0 and 2 into one target with room for 8, 1 into another.
    // Each row asks 4 at site 0 (2 events of 2), 1 at site 1, 3 at site 2.
    auto gpu = gpuBackend();
    rt::HostMemory hostMemory;
    for (rt::Memory* m : {static_cast<rt::Memory*>(&hostMemory), &gpu->memory()}) {
        Emitters e(*m, 2, 3);
        e.write(e.sites.mask, std::vector<uint8_t>{1, 1});
        e.write(e.sites.killed, std::vector<uint8_t>{0, 0});
        e.sites.created = {};
        e.sites.dt = 0.1;
        e.sites.t1 = 1;
        e.sites.nextId = 7;
        const float rate[3] = {20, 10, 30}, count[3] = {2, 1, 1};
        for (size_t s = 0; s < 3; ++s) {
            rt::RateSites::Site& site = e.sites.sites[s];
            e.write(site.accumulated, std::vector<double>{0, 0});
            site.rate = site.count = {};
            site.rateValue = rate[s];
            site.countValue = count[s];
            site.room = s == 1 ? 100 : 8;
        }
        e.sites.sites[2].group = 0;
        m->emitAtRate(e.sites, e.runs);
        auto runs = e.read<uint32_t>(e.runs, rt::runsWords(2, 3));
        const rt::RecordLayout layout(e.sites);
        CHECK(layout.first == std::vector<size_t>{0, 4, 1});  // (the group's records first, row by row)
        CHECK(layout.stride == std::vector<size_t>{2, 1, 2});
        auto record = [&](size_t site, size_t row) { return runs.data() + layout.record(site, row) * rt::kRunWords; };
        // Row 0: site 0 places 0…3 (ids 7…10), site 1 (11), site 2 places 4…6 (12…14);
        // row 1: site 0 place 7 (1 of 4: 15), site 1 (16), site 2 nothing left (of 3).
        const uint32_t expected[3][2][4] = {{{0, 4, 7, 0}, {7, 1, 15, 4}},    // place, kept, id, place in the site
                                            {{0, 1, 11, 0}, {1, 1, 16, 1}},
                                            {{4, 3, 12, 0}, {8, 0, 17, 3}}};
        for (size_t s = 0; s < 3; ++s)
            for (size_t r = 0; r < 2; ++r) {
                INFO("site " << s << ", row " << r);
                const uint32_t* w = record(s, r);
                CHECK(w[0] == expected[s][r][0]);
                CHECK(w[1] == expected[s][r][1]);
                CHECK(w[2] == expected[s][r][2]);
                CHECK(w[rt::kRunSitePlace] == expected[s][r][3]);
            }
        const uint32_t* totals = runs.data() + rt::runsTotalsAt(2, 3);
        CHECK(totals[rt::kTotalsIds] == 10);
        const uint32_t keptAsked[3][2] = {{5, 8}, {2, 2}, {3, 6}};
        for (size_t s = 0; s < 3; ++s) {
            CHECK(totals[rt::kTotalsSites + rt::kTotalsPerSite * s] == keptAsked[s][0]);
            CHECK(totals[rt::kTotalsSites + rt::kTotalsPerSite * s + 1] == keptAsked[s][1]);
        }
    }
}

TEST_CASE("emitters whose emissions the GPU decides: the interpreter's objects, ids, rows and drops") {
    // With rows kept in the memory (SystemOptions::Rows::InMemory), an emitter that never
    // dies and emits at a rate into types that keep their rows there keeps its rows on the
    // GPU too, and its emissions are Memory::emitAtRate's dispatches: rates shared and per
    // row, counts per row, invalid rates (counted), a target at capacity (drops), emitters
    // created in the step by a trigger (their first update's emissions), two sites;
    // emitters that die (some in their first update), their kills late, read where they
    // are, emitters that burst on death, and an emitter of those (the rain); bursts at
    // creation and on edges (the confetti, the fireworks' rockets and their launcher); several
    // sites into one target (the shapes; a small target shared by an emitter and the
    // emitters it emits); an emitter of two types of emitters (which stays on the host);
    // emitters of their own kind, and two of each other (a chain of bursts at creation
    // stays on the host, and so does its maker); children that emit, in sub-steps too. Each with the emitters whose rows it keeps in the memory.
    std::vector<std::pair<std::string, size_t>> programs;
    for (const char* sample : {"fountain", "emitter", "two_streams", "tornado", "shapes"})
        programs.push_back({test::readFile(test::sample(sample)), 1});
    programs.push_back({test::readFile(test::sample("rain")), 2});       // the cloud and its drops
    programs.push_back({test::readFile(test::sample("confetti")), 1});   // bursts on an edge, at creation too
    programs.push_back({test::readFile(test::sample("fireworks")), 2});  // rockets that burst and die on an edge
    programs.push_back({R"(
        @capacity(300) object p(k: float) { point(vec3(k, age, 0), white, 1); kill when age > 0.4; }
        object q { point(vec3(0, age, 1), red, 1); kill when age > 0.3; }
        object e(r: float) {
            emit p(rand() + r) at r per second count 1 + 2 * fract(age);
            emit q at 20 + 10 * sin(age * 7) per second;
        }
        spawn e(900);
        spawn e(-1);
        spawn e(0.25);
        spawn e(45);
        trigger more { emit e(rand() * 200) count 3; })", 1});
    // Two sites into a type of 16 parameter components (its spawn launches write them into
    // the dispatch's words, not in place: their emitters' blocks built on the host).
    programs.push_back({R"(
        @capacity(500) object w(a: vec4, b: vec4, c: vec4, d: vec4) {
            point(a.xyz + b.xyz * age, c, d.x);
            kill when age > 0.3 + d.y;
        }
        object e(r: float) {
            emit w(vec4(r), vec4(rand()), vec4(1, 0, 0, 1), vec4(2, rand(), 0, 0)) at 50 + r per second;
            emit w(vec4(-r), vec4(rand()), vec4(0, 1, 0, 1), vec4(3, 0.1, 0, 0)) at 700 per second count 2;
        }
        spawn e(1);
        spawn e(20);
        spawn e(300);)", 1});
    for (auto [name, emitters] : {std::pair{"emitters_that_die", 1}, {"emitters_burst_on_death", 1},
                                  {"sites_share_a_target", 2}, {"two_kinds_of_emitter_from_one", 3},
                                  {"emitters_burst_at_creation_and_edges", 2}, {"step_emitters_of_their_own_kind", 4},
                                  {"step_children_that_emit", 5}})
        programs.push_back({test::readFile(std::string(PSYS_PROGRAMS_DIR) + "/" + name + ".psys"), emitters});
    for (const auto& [text, expected] : programs) {
        INFO(text.substr(0, 120));
        rt::SystemOptions kept;
        kept.rows = rt::SystemOptions::Rows::InMemory;
        test::Pair p(text, true, false, kept);
        size_t emitters = 0;
        for (size_t t = 0; t < p.gl->typeCount(); ++t)
            emitters += p.gl->pool(t).rowsInMemory() && !p.gl->module().objects[t].emits.empty();
        CHECK(emitters == expected);
        for (int f = 0; f < 90; ++f) {
            if (f == 20 && !p.cpu->module().triggers.empty()) p.fire("more");
            p.steps(1, 1.0 / 60);
            if (f % 15 == 14) p.compare();
        }
        if (text.find("@capacity(300)") != std::string::npos) {
            CHECK(p.stats("p").dropped > 0);
            CHECK(p.gl->stats().invalidEmissions > 0);
            CHECK(p.stats("e").live == 7);
        }
    }
}

TEST_CASE("emitters the GPU decides: a step moves and waits as much for 2,000 of them as for 20") {
    // Their spawn launches are one launch a site from the records (rt::ChildrenLaunch::
    // records), the emitters' blocks built on the GPU: only the totals come back, and
    // the host sends a template, not a block an emitter. Their updates send no emission
    // column in (a rate every row shares, as q's, has no column the GPU keeps).
    struct Steps {  // over the 10 steps measured
        uint64_t bytes, waits, dispatches;
    };
    auto perStep = [](int emitters, const char* death) {
        std::string text = fmt::format(R"(
            object p(k: float) {{ point(vec3(k, age, 0), white, 1); kill when age > 0.3; }}
            object q {{ point(vec3(0, age, 1), red, 1); kill when age > 0.2; }}
            object e(r: float) {{
                emit p(rand() + r) at 20 + r per second count 1 + fract(age);
                emit q at 15 per second;
                {}
            }}
            trigger many(n: float) {{ emit e(rand() * 10) count n; }})", death);
        rt::SystemOptions kept;
        kept.rows = rt::SystemOptions::Rows::InMemory;
        auto gpu = gpuBackend();
        rt::System system(test::compileModule(text), *gpu, kept);
        REQUIRE(system.pool(static_cast<size_t>(system.typeIndex("e"))).rowsInMemory());
        float n = static_cast<float>(emitters);
        REQUIRE_FALSE(system.fire("many", {&n, 1}));
        for (int f = 0; f < 40; ++f) REQUIRE_FALSE(system.step(1.0 / 60));
        Steps before{gpu->transferredBytes(), gpu->waits(), gpu->dispatches()};
        for (int f = 0; f < 10; ++f) REQUIRE_FALSE(system.step(1.0 / 60));
        Steps steps{gpu->transferredBytes() - before.bytes, gpu->waits() - before.waits, gpu->dispatches() - before.dispatches};
        // (Counted after: stats takes the late kills that are ready, which depends on the GPU's timing.)
        CHECK(system.stats().types.at(static_cast<size_t>(system.typeIndex("p"))).live > static_cast<size_t>(emitters));
        return steps;
    };
    // Emitters that never die, and emitters that all die in a step measured (their kills
    // listed where their rows are, only their count coming back, late).
    for (std::string death : {"", "kill when age > 0.75;"}) {
        INFO(death);
        Steps few = perStep(20, death.c_str()), many = perStep(2000, death.c_str());
        MESSAGE(death << " over 10 steps: bytes " << few.bytes << " → " << many.bytes << ", waits " << few.waits << " → " << many.waits << ", dispatches " << few.dispatches << " → " << many.dispatches);
        CHECK(many.waits == few.waits);
        CHECK(many.dispatches == few.dispatches);
        CHECK(many.bytes == few.bytes);
    }
}

// An emission operation whose records or columns pass the GL's largest storage block
// (128 MiB on llvmpipe: 3.7 million emitters at one site; bound whole, the GL drops what
// lies past it, and with it objects) goes as windows of rows, each on from the one before
// (rt::Memory::emissionWindow); a lowered limit makes windows of a dozen emitters here,
// through every use of the records (tests/programs/emissions_in_windows.psys).
TEST_CASE("an emission operation past the GL's largest storage block goes as windows: the interpreter's objects") {
    const std::string text = test::readFile(test::programsDir() + "/emissions_in_windows.psys");
    rt::SystemOptions kept;
    kept.rows = rt::SystemOptions::Rows::InMemory;
    test::Pair pair(text, true, false, kept);
    REQUIRE(pair.gl->pool(static_cast<size_t>(pair.gl->typeIndex("drop"))).rowsInMemory());
    pair.gpu->memory().maxBlockBytes = 2048;  // (4 sites: 13 emitters a window)
    REQUIRE(pair.gpu->memory().emissionWindow(4) == 13);
    REQUIRE_FALSE(pair.cpu->fire("rain", {}));
    REQUIRE_FALSE(pair.gl->fire("rain", {}));
    for (int f = 0; f < 12; ++f) {
        INFO("frame " << f);
        pair.steps(1, 1.0 / 30);
        pair.compare();
    }
    CHECK(pair.stats("splash").dropped > 0);  // (the room ran out part-way, in some window)
    CHECK(pair.stats("drop.bit").created > 400);
}
