// What a step need not wait for, on every backend: kills taken at the end of the step
// (LateKills) against kills taken at once, with a backend that answers late as a device
// does; emission rates and counts every row shares, read from the host's values.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "interp/interpreter.h"
#include "rt/system.h"
#include "run.h"
#include "tests/run_length.h"

using namespace psys;

namespace {

// Answers every late launch (RowsLaunch::late) with a ticket, as a device would, and wipes
// its kill flags: the run-time must take those kills from collect(), at the end of the step
// (an update whose emissions the memory decides keeps them there: RowsLaunch::emissionsStay).
struct LateBackend : rt::Backend {
    interp::Interpreter inner;
    std::map<uint64_t, std::pair<rt::RowsResult, std::vector<uint32_t>>> held;
    std::vector<uint32_t> rows;
    uint64_t next = 1;
    size_t late = 0;
    std::string name() const override { return "late"; }
    rt::Memory& memory() override { return inner.memory(); }
    // As a device: what is drawn is computed after the step (drawing as the step goes reads
    // the kill flags this backend wipes).
    bool rendersInStep() const override { return false; }
    rt::RowsResult run(const rt::RowsLaunch& l) override {
        rt::RowsResult r = inner.run(l);
        if (!l.late) return r;
        std::vector<uint32_t> killed;
        auto* flags = rt::hostData<uint8_t>(inner.memory(), l.columns[rt::ColumnLayout::kKill]);
        for (size_t i = l.begin; i < l.end; ++i)
            if (flags[i]) {
                killed.push_back(static_cast<uint32_t>(i));
                if (!l.emissionsStay) flags[i] = 0;
            }
        held[next] = {r, std::move(killed)};
        ++late;
        return {.ticket = next++};
    }
    void run(const rt::ChildrenLaunch& l) override { inner.run(l); }
    rt::RowsResult collect(uint64_t ticket) override {
        auto [result, killed] = held.at(ticket);
        held.erase(ticket);
        rows = std::move(killed);
        result.killedRows = rows;
        return result;
    }
};

// As a GPU: a late launch's kills clear its pool's alive mask at once (clearsKilled), so
// the run-time may take them at the next settle; its tickets are ready only when `ready`
// says so, and what it collects is counted.
struct OwingBackend : LateBackend {
    bool readyNow = false;
    size_t collected = 0;
    std::string name() const override { return "owing"; }
    bool clearsKilled() const override { return true; }
    bool ready(uint64_t) override { return readyNow; }
    rt::RowsResult run(const rt::RowsLaunch& l) override {
        rt::RowsResult r = LateBackend::run(l);
        if (!r.ticket || !l.aliveMask.valid()) return r;
        auto* alive = rt::hostData<uint8_t>(inner.memory(), l.aliveMask);
        const uint32_t* listed =
            l.aliveRowsBuffer.valid() ? rt::hostData<uint32_t>(inner.memory(), l.aliveRowsBuffer) : l.aliveRows.data();
        for (uint32_t i : held.at(r.ticket).second)
            alive[listed ? listed[i - l.aliveRowsFirst] : i] = 0;
        return r;
    }
    rt::RowsResult collect(uint64_t ticket) override {
        ++collected;
        return LateBackend::collect(ticket);
    }
    using rt::Backend::run;
};

// As the GPU over a pool whose rows are in the memory: a late launch's kills listed in its
// kill list (RowsLaunch::killList: their count, then their rows less `begin`) as it runs,
// so that the run-time only releases them there; what it collects has their count.
struct ListsInMemoryBackend : OwingBackend {
    ListsInMemoryBackend() { readyNow = true; }
    std::string name() const override { return "listing"; }
    rt::RowsResult run(const rt::RowsLaunch& l) override {
        rt::RowsResult r = OwingBackend::run(l);
        if (!r.ticket || !l.killList.valid()) return r;
        auto& [result, killed] = held.at(r.ticket);
        auto* list = rt::hostData<uint32_t>(inner.memory(), l.killList);
        list[0] = static_cast<uint32_t>(killed.size());
        for (size_t k = 0; k < killed.size(); ++k) list[k + 1] = static_cast<uint32_t>(killed[k] - l.begin);
        result.killed = killed.size();
        killed.clear();
        r.killsListed = true;
        return r;
    }
    using rt::Backend::run;
};

// Systems that hold the same objects in the same rows, drawn with the same ids in the same order.
void sameObjects(std::initializer_list<rt::System*> systems) {
    rt::System& a = **systems.begin();
    for (rt::System* b : systems) {
        REQUIRE(test::poolRows(a) == test::poolRows(*b));
        for (size_t t = 0; t < a.typeCount(); ++t) {
            std::vector<rt::RenderPoint> pa = a.points(t), pb = b->points(t);
            REQUIRE(pa.size() == pb.size());
            for (size_t i = 0; i < pa.size(); ++i) REQUIRE(pa[i].id == pb[i].id);
        }
    }
}

}  // namespace

TEST_CASE("kills taken at the end of the step free the rows, in the order, that kills taken at once free" * doctest::test_suite("long")) {
    // Drops, sparks, cells dying in their first update, objects created by triggers: a
    // backend answering late, the kills at the step's end, against the kills at once.
    std::vector<std::string> programs = test::samplesAndPrograms();
    programs.push_back(R"(
        @step(0.01) object leaf { point(vec3(age, 0, 0), white, 1); kill when age > 0.01 + 0.05 * rand(); }
        object root { emit leaf at 3000 per second; }
        trigger boom { emit leaf count 50; }
        spawn root;)");
    // Created before their type's update in the step and dying in their first update: a
    // step that draws as it goes draws them in that update, so they die at once.
    programs.push_back(R"(
        object source { emit flash at 120 per second; }
        object flash { point(vec3(age, 1, 0), white, 1); kill when age > 0.001; }
        spawn source;)");
    size_t late = 0;
    for (const std::string& text : programs) {
        INFO(text.substr(0, 200));
        interp::Interpreter immediateBackend;
        LateBackend lateBackend;
        rt::SystemOptions atOnce;
        atOnce.lateKills = false;
        // c: late kills on a backend that answers at once and draws as the step goes.
        interp::Interpreter listingBackend;
        rt::System a(test::compileModule(text), immediateBackend, atOnce), b(test::compileModule(text), lateBackend),
            c(test::compileModule(text), listingBackend);
        for (int f = 0; f < test::bookkeepingFrames(200); ++f) {
            if (f % 50 == 10)
                for (const ir::Trigger& t : a.module().triggers) {
                    size_t width = 0;
                    for (auto& p : t.params) width += static_cast<size_t>(p.type.width);
                    REQUIRE_FALSE(a.fire(t.name, std::vector<float>(width, 1.5f)));
                    REQUIRE_FALSE(b.fire(t.name, std::vector<float>(width, 1.5f)));
                    REQUIRE_FALSE(c.fire(t.name, std::vector<float>(width, 1.5f)));
                }
            REQUIRE_FALSE(a.step(1.0 / 60));
            REQUIRE_FALSE(b.step(1.0 / 60));
            REQUIRE_FALSE(c.step(1.0 / 60));
            sameObjects({&a, &b, &c});  // drawn every step (a and c as the step goes)
            for (size_t t = 0; t < a.typeCount(); ++t) {
                CHECK(a.stats().types[t].killed == b.stats().types[t].killed);
                CHECK(a.stats().types[t].unstable == b.stats().types[t].unstable);
            }
        }
        CHECK(lateBackend.held.empty());  // every ticket collected
        late += lateBackend.late;
    }
    CHECK(late > 1000);
}

TEST_CASE("rows kept in the memory: the same objects in the same rows as rows kept on the host" * doctest::test_suite("long")) {
    // Pool::keepRowsInMemory through the memory's own operations (rt::Memory::allocateRows,
    // releaseRows, identify, markFresh, scatter by a row list), on a backend that answers
    // at once (kills listed by the run-time) and one that answers late (listed at the end
    // of the step from what it collects), against the rows kept on the host; the samples,
    // the programs, a pool at capacity under a rate of 10^6/s, every object killed in one
    // frame, a burst, triggers.
    std::vector<std::string> programs = test::samplesAndPrograms();
    programs.push_back("@capacity(1000) object s { point(origin, white, age); kill when age > 0.3; }\n"
                       "object e { emit s at 1e6 per second; }\nspawn e;");
    programs.push_back("object s(k: float) { point(vec3(k, 0, 0), white, 1); kill when age > 1; }\n"
                       "object e { emit s(rand()) count 5000; kill; }\nspawn e;");
    programs.push_back("object s { point(vec3(age), white, 1); kill when age > 0.5 * rand(); }\n"
                       "trigger boom { emit s count 20000; }");
    // (Emitters that die and burst on death, decided in the memory: tests/programs.)
    // A trigger's objects half of which die at once: they wait for the next step's end.
    programs.push_back("object s(k: float) { point(vec3(k, 0, 0), white, 1); kill when k < 0.5; }\n"
                       "trigger boom { emit s(rand()) count 5000; }");
    size_t inMemory = 0;
    for (const std::string& text : programs) {
        INFO(text.substr(0, 200));
        rt::SystemOptions onHost, kept;
        onHost.rows = rt::SystemOptions::Rows::OnHost;
        kept.rows = rt::SystemOptions::Rows::InMemory;
        kept.drawInStep = false;  // (a type drawn as the step goes keeps its rows on the host)
        interp::Interpreter hostBackend, keptBackend;
        LateBackend lateBackend;
        ListsInMemoryBackend listsBackend;  // (d: kills listed in the memory as the launch runs, as on the GPU)
        rt::System a(test::compileModule(text), hostBackend, onHost), b(test::compileModule(text), keptBackend, kept),
            c(test::compileModule(text), lateBackend, kept), d(test::compileModule(text), listsBackend, kept);
        for (size_t t = 0; t < b.typeCount(); ++t) inMemory += b.pool(t).rowsInMemory();
        for (int f = 0; f < test::bookkeepingFrames(120); ++f) {
            if (f % 40 == 10)
                for (const ir::Trigger& t : a.module().triggers) {
                    size_t width = 0;
                    for (auto& p : t.params) width += static_cast<size_t>(p.type.width);
                    for (rt::System* s : {&a, &b, &c, &d}) REQUIRE_FALSE(s->fire(t.name, std::vector<float>(width, 1.5f)));
                }
            for (rt::System* s : {&a, &b, &c, &d}) REQUIRE_FALSE(s->step(1.0 / 60));
            d.stats();  // (the deaths it owed at the step's end, as a GPU's: ready, taken)
            sameObjects({&a, &b, &c, &d});
            for (size_t t = 0; t < a.typeCount(); ++t) {
                std::vector<rt::RenderPoint> pa = a.points(t), pb = b.points(t);
                for (size_t i = 0; i < pa.size(); ++i) REQUIRE(pa[i].position == pb[i].position);
                const rt::TypeStats sa = a.stats().types[t];
                for (rt::System* s : {&b, &c, &d}) {
                    const rt::TypeStats sb = s->stats().types[t];
                    CHECK(sa.live == sb.live);
                    CHECK(sa.killed == sb.killed);
                    CHECK(sa.dropped == sb.dropped);
                }
            }
        }
    }
    CHECK(inMemory >= 5);  // drops, sparks, the fire's particles, …
}

TEST_CASE("a trigger's kills freed at the next step's end free the rows its objects took") {
    // Its batch's rows are listed in a buffer the pool lends; the kills of its first update
    // are freed through that list at the next step's end, after the step's own kill lists
    // were written (listed as the launch runs, as on the GPU): the list must still be the
    // batch's then (tests/programs/generated/trigger_kills_after_a_step.psys).
    std::string text = test::readFile(PSYS_PROGRAMS_DIR "/generated/trigger_kills_after_a_step.psys");
    rt::SystemOptions onHost, kept;
    onHost.rows = rt::SystemOptions::Rows::OnHost;
    kept.rows = rt::SystemOptions::Rows::InMemory;
    interp::Interpreter hostBackend;
    ListsInMemoryBackend listsBackend;
    rt::System a(test::compileModule(text), hostBackend, onHost), d(test::compileModule(text), listsBackend, kept);
    REQUIRE(d.pool(0).rowsInMemory());
    const float where[] = {1.247f, -2.725f, 0.24f}, none = 0;
    for (int f = 0; f < 34; ++f) {
        for (rt::System* s : {&a, &d}) {
            if (f == 24) REQUIRE_FALSE(s->fire("fire0", {&none, 1}));
            if (f == 30) REQUIRE_FALSE(s->fire("fire1", where));  // its object dies in its first update
            REQUIRE_FALSE(s->step(1.0 / 60));
        }
        d.stats();  // (what it owed at the step's end: taken)
        INFO("frame " << f);
        sameObjects({&a, &d});
        CHECK(d.stats().types[0].live == a.stats().types[0].live);
    }
    CHECK(a.stats().types[0].live == 1);
    CHECK(a.stats().types[0].killed == 1);
}

TEST_CASE("a hot reload right after a trigger frees the trigger's dead as a pool kept on the host does") {
    // Objects a trigger created that died in their first update wait, listed in the
    // memory, for the next step's end; a reload before it frees them (after the free rows,
    // in row order, as the frozen rows of a pool kept on the host), counts them, and the
    // new system reuses their rows.
    std::string text = test::readFile(PSYS_PROGRAMS_DIR "/generated/trigger_kills_after_a_step.psys");
    rt::SystemOptions onHost, kept;
    onHost.rows = rt::SystemOptions::Rows::OnHost;
    kept.rows = rt::SystemOptions::Rows::InMemory;
    interp::Interpreter hostBackend, hostAfter;
    ListsInMemoryBackend listsBackend, listsAfter;
    rt::System a(test::compileModule(text), hostBackend, onHost), d(test::compileModule(text), listsBackend, kept);
    const float where[] = {1.247f, -2.725f, 0.24f}, none = 0;
    for (rt::System* s : {&a, &d}) {
        for (int f = 0; f < 3; ++f) REQUIRE_FALSE(s->fire("fire0", {&none, 1}));
        REQUIRE_FALSE(s->step(1.0 / 60));
        for (int f = 0; f < 4; ++f) REQUIRE_FALSE(s->fire("fire1", where));  // they die in their first update
    }
    rt::System a2(test::compileModule(text), hostAfter, onHost), d2(test::compileModule(text), listsAfter, kept);
    a2.carryOver(a);
    d2.carryOver(d);
    CHECK(d2.stats().types[0].killed == a2.stats().types[0].killed);
    CHECK(a2.stats().types[0].killed == 4);
    for (int f = 0; f < 3; ++f) {
        for (rt::System* s : {&a2, &d2}) {
            REQUIRE_FALSE(s->fire("fire0", {&none, 1}));
            REQUIRE_FALSE(s->step(1.0 / 60));
        }
        d2.stats();
        sameObjects({&a2, &d2});
    }
    CHECK(a2.pool(0).rows() == 7);  // the four rows of the dead taken again
}

namespace {

// Writes NaN over the emission columns of every update at a uniform clock, after it ran:
// what the run-time reads of them then is NaN (an invalid emission).
struct PoisonedEmissions : rt::Backend {
    interp::Interpreter inner;
    std::string name() const override { return "poisoned"; }
    rt::Memory& memory() override { return inner.memory(); }
    rt::RowsResult run(const rt::RowsLaunch& l) override {
        rt::RowsResult r = inner.run(l);
        if (l.kernel->kind != ir::KernelKind::Update || l.clock.perRow()) return r;
        for (int c = l.layout->emits; c < l.layout->render; ++c)
            if (rt::Buffer b = l.columns[static_cast<size_t>(c)]; b.valid())
                std::fill(rt::hostData<float>(inner.memory(), b) + l.begin, rt::hostData<float>(inner.memory(), b) + l.end, NAN);
        return r;
    }
    void run(const rt::ChildrenLaunch& l) override { inner.run(l); }
};

}  // namespace

TEST_CASE("an emission rate or count every row shares is read from the host's values, not its column") {
    const std::string shared = R"(
        extern rate: float = 90;
        object p { point(vec3(0), white, 1); kill when age > 0.5; }
        object e { emit p at rate / 3 per second count 2; }
        spawn e; spawn e; spawn e;)";
    ir::Module module = test::compileModule(shared);
    const ir::Object& e = module.objects.at(static_cast<size_t>(module.objectIndex("e")));
    rt::ColumnLayout layout = rt::columnLayout(e, *e.kernel(ir::KernelKind::Update));
    using From = rt::ColumnLayout::Shared::From;
    REQUIRE(layout.emitShared.size() == 2);
    CHECK(layout.emitShared[0].from == From::Uniform);  // rate / 3: a value of the uniform kernel
    CHECK(layout.emitShared[1].from == From::Constant);
    CHECK(layout.emitShared[1].value == 2);
    CHECK(e.kernel(ir::KernelKind::Update)->findOne(ir::YieldKind::Kill) == nullptr);  // it never dies
    // The run-time takes them from there: poisoned columns change nothing…
    auto created = [](const std::string& text, rt::Backend& backend) {
        rt::System system(test::compileModule(text), backend);
        for (int f = 0; f < 60; ++f) REQUIRE_FALSE(system.step(1.0 / 60));
        return std::pair{system.stats().types.at(0).created, system.stats().invalidEmissions};
    };
    interp::Interpreter plain;
    PoisonedEmissions poisoned;
    CHECK(created(shared, poisoned) == created(shared, plain));
    CHECK(created(shared, plain).first == 3 * 2 * 30);
    // An extern as it is (`at rate per second`): the run-time reads the extern.
    std::string asExtern = shared;
    asExtern.replace(asExtern.find("rate / 3"), 8, "rate");
    ir::Module externModule = test::compileModule(asExtern);
    const ir::Object& e2 = externModule.objects.at(static_cast<size_t>(externModule.objectIndex("e")));
    CHECK(rt::columnLayout(e2, *e2.kernel(ir::KernelKind::Update)).emitShared[0].from == From::Extern);
    CHECK(created(asExtern, poisoned) == created(asExtern, plain));
    CHECK(created(asExtern, plain).first == 3 * 2 * 90);
    // …while a rate each row has its own is read from its column (so the poison shows).
    std::string ownRate = R"(
        extern rate: float = 90;
        object p { point(vec3(0), white, 1); kill when age > 0.5; }
        object e { emit p at rate / 3 + rand() per second count 2; }
        spawn e; spawn e; spawn e;)";
    CHECK(created(ownRate, poisoned).second > 0);
}

TEST_CASE("a step's deaths a device still owes are settled by the next settle that may wait, and by stats only when ready") {
    // Drops that die at 0.4 s from a stream, on a backend that owes every late launch's
    // kills until asked to wait (the GPU's way), against the interpreter: what is drawn is
    // the same at once (its kills cleared the alive mask); the rows freed, the live counts
    // and the ids after a settle that may wait — the next step's first phase (a step of no
    // time runs it alone), a trigger before its objects take rows, finish — or once the
    // backend says its tickets are ready (stats, finished); never a wait before.
    const char* text = "object drop { point(vec3(age), white, 1); kill when age > 0.4; }\n"
                       "object stream { emit drop at 600 per second; }\n"
                       "trigger burst { emit drop count 50; }\nspawn stream;";
    interp::Interpreter host;
    OwingBackend owing;
    rt::SystemOptions options;
    options.rows = rt::SystemOptions::Rows::OnHost;  // (the rows compared are the host's)
    rt::System a(test::compileModule(text), host, options), b(test::compileModule(text), owing, options);
    auto drawnSame = [&] { REQUIRE(a.points(0).size() == b.points(0).size()); };
    for (int f = 0; f < 40; ++f) {
        REQUIRE_FALSE(a.step(1.0 / 60));
        REQUIRE_FALSE(b.step(1.0 / 60));
        drawnSame();
    }
    size_t collected = owing.collected;
    CHECK(b.stats().types[0].killed < a.stats().types[0].killed);  // owed: not ready, not waited for
    CHECK_FALSE(b.finished());
    CHECK(owing.collected == collected);
    REQUIRE_FALSE(b.step(0));  // the settle phase alone: everything owed taken and freed
    REQUIRE_FALSE(a.step(0));
    CHECK(owing.collected > collected);
    CHECK(b.stats().types[0].killed == a.stats().types[0].killed);
    CHECK(test::poolRows(a) == test::poolRows(b));
    for (int f = 0; f < 10; ++f) {
        REQUIRE_FALSE(a.step(1.0 / 60));
        REQUIRE_FALSE(b.step(1.0 / 60));
    }
    REQUIRE_FALSE(a.fire("burst", {}));  // its objects take the rows the last step freed
    REQUIRE_FALSE(b.fire("burst", {}));
    CHECK(test::poolRows(a) == test::poolRows(b));
    sameObjects({&a, &b});
    REQUIRE_FALSE(a.step(1.0 / 60));
    REQUIRE_FALSE(b.step(1.0 / 60));
    owing.readyNow = true;  // stats takes what is ready
    collected = owing.collected;
    CHECK(b.stats().types[0].killed == a.stats().types[0].killed);
    CHECK(owing.collected > collected);
    CHECK(test::poolRows(a) == test::poolRows(b));
    owing.readyNow = false;
    REQUIRE_FALSE(a.step(1.0 / 60));
    REQUIRE_FALSE(b.step(1.0 / 60));
    a.finish();
    b.finish();  // waits for everything
    CHECK(b.stats().types[0].killed == a.stats().types[0].killed);
    CHECK(b.stats().types[0].live == a.stats().types[0].live);
    sameObjects({&a, &b});
}
