// Creating objects in batches: the same objects, ids, rows and values as creating them
// one by one (rt/system_create.cpp, rt/system_queue.cpp).
#include <doctest/doctest.h>

#include <filesystem>
#include <map>
#include <string>

#include "rt/system.h"
#include "run.h"
#include "tests/differential.h"
#include "test_support.h"

using namespace psys;
using test::bitwise;
using test::compareRuns;
using test::Run;

TEST_CASE("creating objects in batches gives the run of creating them one by one, bit for bit") {
    rt::SystemOptions oneByOne;
    oneByOne.createInBatches = false;
    size_t points = 0;
    for (auto& entry : std::filesystem::directory_iterator(PSYS_SAMPLES_DIR)) {
        if (entry.path().extension() != ".psys") continue;
        INFO(entry.path().filename().string());
        std::string text = test::readFile(entry.path().string());
        Run a(text, oneByOne), b(text);
        // Every kind of creation each type has (its rates, bursts, deaths) within the
        // frames test::coverFrames gives: batches and one by one create alike after them.
        points += compareRuns(a, b, test::coverFrames(text, test::kLongRun), bitwise);
    }
    CHECK(points > 30000);
    // At capacity, objects that emit their own type while being created: an object's
    // emissions see the rows allocated for the objects after it as free, as one by one.
    std::string selfEmitting = R"(
        @capacity(200) object cell {
            point(vec3(rand(), rand(), 0) * age, white, age);
            emit cell at 90 per second;
            kill when age > 0.5 + rand();
        }
        spawn cell;)";
    rt::SystemOptions small = oneByOne;
    Run c(selfEmitting, small), d(selfEmitting);
    CHECK(compareRuns(c, d, 300, bitwise) > 10000);
    CHECK(d.stats("cell").dropped > 0);
}

TEST_CASE("a step creates each type that emits nothing in one batch, however many emitters ask, as one by one") {
    // Three sources, each emitting two types: the queue holds spark, puff, spark, puff, …
    // Neither emits nor reads a parent, so their runs are created a type at a time: one
    // batch of each a step (six before), the same objects, ids, rows and values as
    // creating them one by one — sparks dropped at their capacity included.
    std::string text = R"(
        @capacity(60) object spark(p: vec3) {
            pos = snapshot(p) + integrate(vec3(0, -1, 0));
            point(pos, white, 1);
            kill when age > 0.3 + rand() * 0.2;
        }
        object puff(x: float) {
            point(vec3(x, age, rand()), white, 1);
            kill when age > 0.25;
        }
        object source(x: float) {
            emit spark(vec3(x, rand(), 0)) at 150 per second;
            emit puff(x + rand()) at 70 per second;
        }
        spawn source(0);
        spawn source(1);
        spawn source(2);)";
    rt::SystemOptions oneByOne;
    oneByOne.createInBatches = false;
    Run a(text, oneByOne), b(text);
    CHECK(compareRuns(a, b, 120, bitwise) > 5000);
    CHECK(b.stats("spark").dropped > 0);
    // The first updates of new objects (a creation's clock: per row) of each type, per step.
    std::map<std::string, int> batches;
    test::WatchedInterpreter backend([&](const rt::RowsLaunch& l) {
        if (l.kernel->kind == ir::KernelKind::Update && l.clock.dt == rt::Clock::Source::SinceCreated)
            ++batches[l.object->name];
    });
    rt::SystemOptions oneThread;  // (a batch is a launch: one chunk)
    oneThread.threads = 1;
    rt::System system(test::compileModule(text), backend, oneThread);
    for (int f = 0; f < 6; ++f) {  // (45 sparks by then: none dropped yet)
        batches.clear();
        REQUIRE_FALSE(system.step(test::kFrame));
        CHECK(batches["spark"] == 1);
        CHECK(batches["puff"] == 1);
    }
}

TEST_CASE("a generation's runs are created type by type, in batches as one by one: an emitter of two types of emitters") {
    // tests/programs/two_kinds_of_emitter_from_one.psys: e queues b, a, b, a, … (its sites'
    // order, an emitter at a time); both create a's before b's, whose x's fill x's pool.
    std::string text = test::readFile(std::string(PSYS_PROGRAMS_DIR) + "/two_kinds_of_emitter_from_one.psys");
    rt::SystemOptions oneByOne;
    oneByOne.createInBatches = false;
    Run a(text, oneByOne), b(text);
    CHECK(compareRuns(a, b, 120, bitwise) > 5000);
    CHECK(b.stats("x").dropped > 0);
}

TEST_CASE("a new emitter in sub-steps emits with its values as of each sub-step, its rows on the host or in the memory") {
    // Each b is created inside a step of 1/20 s and takes its first update in sub-steps of
    // 1/200 s, emitting a c every 1/100 s with its x (an integral: a value of its state,
    // not recomputed from its age). A c's x0 − (b.age − age) is b's age at the end of
    // the sub-step that emitted it less b's age at the c's creation: in [0, 1/200). Where
    // the sub-steps' emissions read b's values after the batch, they read the last
    // sub-step's: up to 1/20 s.
    std::string text = R"(
        object src { emit b at 7 per second; }
        @step(1 / 200)
        object b {
            x = integrate(1);
            emit c(x) at 100 per second;
            object c(x0: float) {
                point(vec3(x0 - (b.age - age), 0, 0), white, 1);
                kill when age > 0.04;
            }
        }
        spawn src;)";
    for (bool inMemory : {false, true}) {
        INFO("rows in the memory: " << inMemory);
        Run run(text, inMemory ? test::rowsInMemory() : rt::SystemOptions{});
        CHECK(run.system->pool(run.type("b")).rowsInMemory() == inMemory);
        size_t seen = 0;
        for (int f = 0; f < 12; ++f) {
            run.steps(1, 1.0 / 20);
            for (const rt::RenderPoint& p : run.points("b.c")) {
                CHECK(p.position[0] > -1e-5f);
                CHECK(p.position[0] < 1.0f / 200 + 1e-5f);
                ++seen;
            }
        }
        CHECK(seen > 20);
    }
}

// A memory whose buffers an operation binds are limited (a GPU's storage blocks) decides
// a large emission operation as windows of rows, each on from the totals of the one
// before (rt::Memory::emissionWindow, RateSites::carry). On the host the limit is lowered
// to a dozen emitters a window: the same objects, ids, rows and values as one operation
// (tests/programs/emissions_in_windows.psys says what it goes through).
TEST_CASE("an emission operation in windows of rows gives the objects of one operation, bit for bit") {
    const std::string text = test::readFile(std::string(PSYS_PROGRAMS_DIR) + "/emissions_in_windows.psys");
    test::Run whole(text, test::rowsInMemory()), windows(text, test::rowsInMemory());
    windows.backend.memory().maxBlockBytes = 2048;
    REQUIRE(windows.backend.memory().emissionWindow(4) == 13);
    const size_t points = test::compareRuns(whole, windows, 20, test::bitwise);
    CHECK(points > 1000);
    CHECK(test::sameRows(*whole.system, *windows.system));
    CHECK(windows.stats("splash").dropped > 0);
    CHECK(windows.system->pool(windows.type("drop")).rowsInMemory());
}

TEST_CASE("a step's bookkeeping over more rows than a piece gives the same rows, ids and values on 1 and 4 threads") {
    // 75,000 objects created a step, about 20,000 of them dying in their first update and
    // the rest within 0.03 s, scattered: allocate, the freeze of a kill list and its
    // release run in pieces of detail::kHostRows (16,384) rows on every thread, each
    // piece's place on the free stack from the counts before it. The memory's
    // own bookkeeping (rows in the memory: Memory::releaseRows, in order, one thread) is
    // the reference: a piece's rows in another place would hand later objects other rows,
    // and the points, in row order, would differ.
    std::string text = R"(
        @capacity(200000) object p {
            pos = integrate(nrand3());
            point(pos, white, 1);
            kill when age > rand() * 0.03;
        }
        object e { emit p at 4500000 per second; }
        spawn e;)";
    rt::SystemOptions pieces, inOrder = test::rowsInMemory();
    pieces.threads = 4;
    pieces.drawInStep = false;
    inOrder.threads = 1;
    {
        Run a(text, pieces), b(text, inOrder);
        REQUIRE_FALSE(a.system->pool(a.type("p")).rowsInMemory());
        REQUIRE(b.system->pool(b.type("p")).rowsInMemory());
        CHECK(compareRuns(a, b, 10, bitwise) > 300000);
        CHECK(a.stats("p").killed > 600000);
    }
    // As many emitters, each emitting at a rate and at its death: the kill flags read and
    // the rows' emissions decided in pieces on every thread, queued in row order (ids).
    std::string emitters = R"(
        object q(from: vec3) { point(from + vec3(0, age, 0), white, 1); kill when age > 0.03; }
        @capacity(200000) object p {
            pos = integrate(nrand3());
            point(pos, white, 1);
            emit q(pos) at 20 + 40 * rand() per second;
            kill when age > 0.02 + rand() * 0.06;
            on death { emit q(pos) count 1; }
        }
        object e { emit p at 1500000 per second; }
        spawn e;)";
    Run a(emitters, pieces), b(emitters, inOrder);
    CHECK(b.system->pool(b.type("p")).rowsInMemory());
    CHECK(compareRuns(a, b, 8, bitwise) > 300000);
    CHECK(a.stats("q").created > 100000);
}
