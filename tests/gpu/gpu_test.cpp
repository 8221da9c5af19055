// The GLSL backend against the interpreter, on whatever OpenGL 4.5 the machine has (Mesa's
// llvmpipe in CI): every sample and the every-operation program for 600 frames (triggers
// fired), and the extremes of docs/runtime.md. Both must create, kill and draw the same
// objects with the same ids.
//
// The tolerances. The shaders compute + − × ÷, comparisons, floor, mod, min, max, the
// random draws and the ages as the interpreter does, bit for bit (`precise`: no fused
// multiply-add, no reordering; the hash in 32-bit integers; ages from doubles). What
// differs is the GL's own sin, cos, tan, asin, acos, atan, exp, log, pow and sqrt, which
// GLSL 4.50 asks little of (§4.7.1: atan, and asin and acos with it, within 4096 ulp, a
// relative 4.9e-4; exp and log within 3 + 2·|x| ulp; pow as exp2(y·log2 x)); llvmpipe
// computes them with its own polynomials (its asin is good to about 1e-4).
//   - The samples use sin, cos, exp, pow and sqrt gently: measured 7.1e-6 at worst
//     (relative to max(1, |value|)) after 600 frames. Tolerance 1e-4.
//   - Except marbles: a bounce off a sphere turns with the normal at the contact (a
//     sqrt), and every later bounce multiplies a difference in it: measured 1.3e-4 after
//     600 frames. Tolerance 1e-3.
//   - The every-operation program feeds asin, acos and atan (their 4.9e-4) into pow as a
//     base with exponents up to about 10, which multiplies a relative error by the
//     exponent: measured 2.5e-3. Tolerance 1e-2.
// A wrong operation, lane, column or draw is off by the size of the value itself, far
// beyond both.
#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "codegen_glsl/glsl_shaders.h"
#include "gpu/compact.h"
#include "gpu/glsl_backend.h"
#include "interp/interpreter.h"
#include "tests/differential.h"
#include "tests/run_length.h"
#include "tests/system_support.h"
#include "tests/unexpected_op.h"
#include "gpu_support.h"

using namespace psys;
using namespace psys::test;


TEST_CASE("every sample draws the same on the GPU as on the interpreter, for 600 frames (200 sanitized)" * doctest::test_suite("long")) {
    double worst = 0;
    for (auto& entry : std::filesystem::directory_iterator(test::samplesDir())) {
        if (entry.path().extension() != ".psys") continue;
        INFO(entry.path().filename().string());
        // (marbles: bounces in a row amplify the GL's last bits, above)
        double tolerance = entry.path().stem() == "marbles" ? 1e-3 : kSamplesTolerance;
        std::string text = readFile(entry.path());
        test::Comparison c = compareProgram(text, test::sweepFrames(text), true, tolerance);
        CHECK(c.points > 0);
        MESSAGE(entry.path().filename().string() << ": " << c.points << " points, " << c.differences
                                                 << " not bit for bit, worst " << c.worst);
        worst = std::max(worst, c.worst);
    }
    MESSAGE("the samples' worst difference: " << worst);
}

TEST_CASE("the step's bookkeeping programs (tests/programs/step_*) on the GPU, with its host side and without") {
    // Deaths settled beside bursts, triggers fired mid-run, late kills and nested types:
    // each program once crashed the GLSL backend.
    size_t programs = 0;
    for (auto& entry : std::filesystem::directory_iterator(test::programsDir())) {
        if (!entry.path().filename().string().starts_with("step_")) continue;
        ++programs;
        for (bool hostSide : {false, true}) {
            INFO(entry.path().filename().string() << (hostSide ? " with the host side" : ""));
            compareProgram(readFile(entry.path()), 120, true, kSamplesTolerance, hostSide, 10);
        }
    }
    CHECK(programs >= 3);
}

TEST_CASE("bs3 on the GPU takes the interpreter's steps, each object its own") {
    // Drops under drags from none to stiff: each object's step shrinks as far as its drag
    // asks. Only + − × ÷ and comparisons decide a step (opt/integrate_adaptive.cpp), which
    // the shaders compute bit for bit: the same steps, the same points.
    const char* text = R"(
        @integrator(bs3) @tolerance(1e-3, 2)
        object drop(k: float) {
            pos = vec3(0, 1, 0) + integrate(vel);
            vel = vec3(1, 2, 0) + integrate(vec3(0, -9.8, 0) - k * vel);
            point(pos, white, 1);
            kill when age > 2;
        }
        object source { emit drop(rand() * 400) at 120 per second; }
        spawn source;)";
    test::Comparison c = compareProgram(text, 240, true, 0);
    CHECK(c.points > 20000);
    CHECK(c.differences == 0);
}

TEST_CASE("@precision(double) on the GPU: the interpreter's bits") {
    // Pair arithmetic in the shaders (their values are `precise`: nothing contracted or
    // reordered), far from the origin, through sqrt, pow and division.
    test::Comparison c = compareProgram(readFile(programsDir() + "/double_precision.psys"), 240, true, 0);
    CHECK(c.points > 1000);
    CHECK(c.differences == 0);
}

TEST_CASE("a launch split over dispatches computes what one dispatch computes") {
    // Where a pool outgrows a storage block, a launch runs as several dispatches; each
    // binds the columns it reads and writes in place from an aligned offset before its
    // first row. 99 rows a dispatch: first rows at every alignment.
    for (const char* sample : {"fountain", "fire", "fireworks"}) {
        INFO(sample);
        Pair p(readFile(test::sample(sample)));
        p.gpu->limitDispatchRows(99);
        for (int f = 0; f < 150; ++f) {
            p.steps(1, 1.0 / 60);
            p.compare();  // and takes what the GPU still owes
            // Kills taken late (several dispatches each) free the rows the interpreter
            // frees, in its order: the same rows, generations and ids.
            REQUIRE(test::poolRows(*p.cpu) == test::poolRows(*p.gl));
        }
        size_t rows = 0;
        for (size_t t = 0; t < p.gl->typeCount(); ++t) rows = std::max(rows, p.gl->pool(t).rows());
        CHECK(rows > 3 * 99);
    }
}

TEST_CASE("a reload on the GPU carries every object on, the old system's last draws still uncounted") {
    // As the viewer reloads: a new system on the same backend takes the old one's objects
    // over, right after the old one drew (its counts not yet taken), and the old one goes.
    // With the host side too: the emitters' columns on the host carried over.
    for (bool hostSide : {false, true})
    for (const char* sample : {"fountain", "fireworks", "follow_parent"}) {
        INFO(std::string(sample) << (hostSide ? ", host side" : ""));
        std::string text = readFile(test::sample(sample));
        interp::Interpreter interpreter;
        auto gpu = gpuBackend(hostSide);
        rt::System straight(test::compileModule(text), interpreter);
        auto before = std::make_unique<rt::System>(test::compileModule(text), *gpu);
        for (int f = 0; f < 90; ++f) {
            REQUIRE_FALSE(straight.step(1.0 / 60));
            REQUIRE_FALSE(before->step(1.0 / 60));
            for (size_t t = 0; t < before->typeCount(); ++t) before->draw(t);
        }
        size_t uncounted = 0;
        for (size_t t = 0; t < before->typeCount(); ++t) uncounted += !before->draw(t).counted;
        if (std::string(sample) != "follow_parent") CHECK(uncounted > 0);  // (its sprites' draws answer at once)
        rt::System after(test::compileModule(text), *gpu);
        rt::ReloadReport report = after.carryOver(*before);
        CHECK(report.dropped == 0);
        before.reset();
        test::Comparison c = test::compareSystems(straight, after, 200);
        CHECK(c.points > 1000);
        CHECK(c.worst <= kSamplesTolerance);
        CHECK(test::poolRows(straight) == test::poolRows(after));
    }
}

TEST_CASE("every operation computes on the GPU what the interpreter computes") {
    std::string text = readFile(test::programsDir() + "/every_operation.psys");
    for (bool optimize : {false, true}) {
        test::Comparison c = compareProgram(text, 300, optimize, kEveryOperationTolerance);
        CHECK(c.points > 1000);
        MESSAGE(std::string(optimize ? "every operation (optimized): " : "every operation: ") << c.points << " points, worst "
                                                                                    << c.worst);
    }
}

TEST_CASE("min, max and clamp on NaN and signed zeros: the GPU picks the interpreter's operand") {
    std::string text = readFile(test::programsDir() + "/nan_edges.psys");
    for (bool optimize : {false, true}) {
        test::Comparison c = compareProgram(text, 10, optimize, 0);
        CHECK(c.points == 20);
        CHECK(c.differences == 0);
    }
}

TEST_CASE("the GPU at the extremes of docs/runtime.md") {
    SUBCASE("capacity overflow: the pool stays full and the spawns beyond it are counted") {
        Pair p("@capacity(1000) object s { point(origin, white, age); kill when age > 2; }\n"
               "object e { emit s at 1e6 per second; }\nspawn e;");
        for (int f = 0; f < 180; ++f) {
            p.steps(1, 1.0 / 60);
            p.compare();
        }
        CHECK(p.stats("s").live == 1000);
        CHECK(p.stats("s").dropped > 1'000'000);
    }
    SUBCASE("every object killed in one frame") {
        Pair p("object s(k: float) { point(vec3(k, 0, 0), white, 1); kill when age > 1; }\n"
               "object e { emit s(rand()) count 5000; kill; }\nspawn e;");
        p.steps(59, 1.0 / 60);
        p.compare();
        CHECK(p.stats("s").live == 5000);
        p.steps(2, 1.0 / 60);
        p.compare();
        CHECK(p.stats("s").live == 0);
        CHECK(p.stats("s").killed == 5000);
    }
    SUBCASE("a burst of 100k in one frame") {
        Pair p("object s { v = nrand3(); pos = integrate(v); point(pos, white, age); }\n"
               "trigger boom { emit s count 100000; }");
        p.steps(1, 1.0 / 60);
        p.fire("boom");
        p.steps(3, 1.0 / 60);
        p.compare();
        CHECK(p.stats("s").live == 100000);
    }
    SUBCASE("a rate of 0.25 per second emits at 4 s, 8 s, 12 s") {
        Pair p("object s { point(origin, white, age); }\nobject e { emit s at 0.25 per second; }\nspawn e;");
        for (int frame = 1; frame <= 60 * 12; ++frame) {
            p.steps(1, 1.0 / 60);
            REQUIRE_MESSAGE(p.stats("s").created == static_cast<uint64_t>(frame / 240), "frame " << frame);
        }
        p.compare();
    }
    SUBCASE("dt = 0 changes nothing, and a 10 s hitch") {
        Pair p("object s { pos = integrate(vec3(1, 2, 3)); point(pos, white, age); kill when age > 3; }\n"
               "object e { emit s at 100 per second; }\nspawn e;");
        p.steps(30, 1.0 / 60);
        auto before = p.gl->points(0);
        p.steps(10, 0.0);
        CHECK(p.gl->points(0).size() == before.size());
        p.compare();
        p.steps(1, 10.0);
        p.compare();
        CHECK(p.stats("s").live == doctest::Approx(300).epsilon(0.01));
    }
    SUBCASE("after 10^7 s ages are exact to a millisecond") {
        Pair p("object a { point(origin, white, age); }\ntrigger go { emit a count 1; }");
        p.steps(1, 1e7);
        p.fire("go");
        p.steps(1, 0.001);
        p.compare();
        auto points = p.gl->points(0);
        REQUIRE(points.size() == 1);
        CHECK(points[0].size == doctest::Approx(0.001).epsilon(1e-3));
    }
    SUBCASE("NaN in an extern is refused; a point that is not finite is not drawn") {
        Pair p("extern w: vec3 = 0;\nobject a(k: float) { point(vec3(k) / k + w, white, 1); }\n"
               "spawn a(0); spawn a(1);");
        float bad[3] = {std::nanf(""), 0, INFINITY};
        CHECK(p.cpu->setExtern("w", bad).has_value());
        CHECK(p.gl->setExtern("w", bad).has_value());
        p.steps(1, 1.0 / 60);
        p.compare();
        CHECK(p.gl->points(0).size() == 1);  // a(0) is 0/0
        CHECK(p.gl->stats().nonFiniteRender == 1);
        CHECK(p.gl->stats().nonFiniteExterns == 1);
    }
}

TEST_CASE("a parent's children read it live on the GPU, then frozen after it dies") {
    Pair p(R"(
        object rocket {
            pos = integrate(vec3(0, 10, 0));
            point(pos, white, 1);
            emit spark at 50 per second;
            kill when age > 1;
            object spark {
                p = rocket.pos + vec3(age, 0, 0);
                point(p, rocket.alive ? red : blue, 1);
                kill when age > 2;
            }
        }
        spawn rocket;)");
    for (int f = 0; f < 150; ++f) {
        p.steps(1, 1.0 / 60);
        p.compare();
    }
    CHECK(p.gl->stats().types.at(1).created > 40);
}


TEST_CASE("the children of a type's emitters are computed in one dispatch a step, as the interpreter computes them") {
    // 40 fans, each with its own parameter, state, id, rate and random numbers, their
    // sparks' arguments reading all of them and the fans' parent: one spawn dispatch for
    // all the fans that emit in a step (a launch block each), not one a fan.
    Pair p(R"(
        object hub {
            swirl = sin(age * 3);
            emit fan(rand() * 4 + 1) count 40;
            object fan(k: float) {
                pos = vec3(k, 0, 0) + integrate(vec3(0, k * 0.1, 0));
                emit spark(pos + vec3(rand(), hub.swirl, k)) at 20 * k per second;
                kill when age > 3;
                object spark(p: vec3) {
                    point(p + vec3(0, age, 0), white, 1);
                    kill when age > 0.5;
                }
            }
        }
        spawn hub;)");
    p.gpu->timePasses(true);
    const int frames = 60;
    for (int f = 0; f < frames; ++f) {
        p.steps(1, 1.0 / 60);
        p.compare();
    }
    const gpu::GlslBackend::PassTime& spawn = p.gpu->passTimes().at("spawn");
    MESSAGE("spawn dispatches: " << spawn.launches << " for " << spawn.rows << " children in " << frames << " steps");
    CHECK(p.stats("hub.fan.spark").created > 1000);
    CHECK(spawn.rows == p.stats("hub.fan.spark").created + p.stats("hub.fan").created);  // nothing dropped
    CHECK(spawn.launches <= frames + 1);  // the hub's burst, then a dispatch a step at most
    CHECK(p.gpu->passTimes().count("arguments adopted") == 0);  // the arguments written in place
}


TEST_CASE("children with more argument components than storage blocks get them through the launch's words") {
    // 16 components (codegen_glsl::kDirectSlots is 14): the spawn shader writes them into
    // the launch's words, copied to the argument columns after; fewer are written in place.
    Pair p(R"(
        object fan(k: float) {
            emit spark(vec4(k), vec4(k, 1, 2, 3) * age, vec4(rand()), vec4(k, k, 0, 1)) at 40 * k per second;
            object spark(a: vec4, b: vec4, c: vec4, d: vec4) {
                point(a.xyz + b.xyz + c.xyz, d, 1);
                kill when age > 0.3;
            }
        }
        object hub { emit fan(rand() + 1) count 8; }
        spawn hub;)");
    p.gpu->timePasses(true);
    for (int f = 0; f < 30; ++f) {
        p.steps(1, 1.0 / 60);
        p.compare();
    }
    CHECK(p.stats("fan.spark").created > 100);
    // (The fans' one in place.) Besides, adopted as the columns of the update's words: the
    // fans' rates, 8 rows a launch — the memory decides their emissions where they are —
    // at their creation and in every update.
    CHECK(p.gpu->passTimes().at("arguments adopted").rows == 16 * p.stats("fan.spark").created);
    CHECK(p.gpu->passTimes().at("adopt").rows == 8 * (30 + 2));
}


TEST_CASE("an object's state stays on the GPU from step to step") {
    // The fountain's drops: 40 bytes of state each (position, velocity, colour), read and
    // written every step, their masks, creation times, ids and rows: all stay on the GPU
    // (the pool's rows are kept there: rows_test.cpp). A step moves the runs of its
    // emissions up and the kills' counts down; their arguments are computed on the GPU.
    auto gpu = gpuBackend();
    rt::System system(test::compileModule(readFile(test::sample("fountain"))), *gpu);
    for (int f = 0; f < 120; ++f) REQUIRE_FALSE(system.step(1.0 / 60));
    size_t live = system.pool(static_cast<size_t>(system.typeIndex("drop"))).live();
    uint64_t before = gpu->transferredBytes(), staged = gpu->stagedBytes();
    for (int f = 0; f < 10; ++f) REQUIRE_FALSE(system.step(1.0 / 60));
    double perDrop = static_cast<double>(gpu->transferredBytes() - before) / 10 / static_cast<double>(live);
    MESSAGE("bytes between host and GPU per drop per step: " << perDrop);
    CHECK(perDrop < 0.2);
    CHECK(perDrop > 0);
    // On the GPU, the update reads and writes the state where it lives (bound in place),
    // not through copies into the launch's words and back (92 bytes a drop: state both
    // ways, creation time, mask): what is copied is for the drops being created.
    double stagedPerDrop = static_cast<double>(gpu->stagedBytes() - staged) / 10 / static_cast<double>(live);
    MESSAGE("bytes copied on the GPU per drop per step: " << stagedPerDrop);
    CHECK(stagedPerDrop < 4);
}

TEST_CASE("a column on the GPU grows into its buffer's zeroed room without GL work, its new rows zero") {
    // A pool grows every step while its population rises: the GL buffer doubles and is
    // zeroed past the rows once; growing within it records nothing (no "grow" pass).
    auto gpu = gpuBackend();
    auto& memory = static_cast<gpu::GlMemory&>(gpu->memory());
    rt::Buffer host = memory.create(rt::Elem::F32, 100), column = memory.create(rt::Elem::F32, 100);
    std::vector<float> ones(100, 1);
    std::vector<uint32_t> all(100);
    for (uint32_t r = 0; r < 100; ++r) all[r] = r;
    memory.write(host, 0, 100, ones.data());
    memory.scatter(host, 0, column, all);
    REQUIRE(memory.onDevice(column));
    gpu->timePasses(true);
    auto grown = [&] {
        auto t = gpu->passTimes().find("grow");
        return t == gpu->passTimes().end() ? size_t{0} : t->second.launches;
    };
    memory.resize(column, 101);  // a new GL buffer of 200 rows, zeroed past the 100
    CHECK(grown() == 1);
    memory.resize(column, 150);
    memory.resize(column, 200);
    CHECK(grown() == 1);
    std::vector<float> out(200);
    memory.read(column, 0, 200, out.data());
    CHECK(std::all_of(out.begin(), out.begin() + 100, [](float x) { return x == 1; }));
    CHECK(std::all_of(out.begin() + 100, out.end(), [](float x) { return x == 0; }));
    memory.resize(column, 201);  // past it: a new buffer
    CHECK(grown() == 2);
}

TEST_CASE("a gather reads rows of a column where it lives: on the GPU without a read-back, 0 for a skipped row") {
    auto gpu = gpuBackend();
    auto& memory = static_cast<gpu::GlMemory&>(gpu->memory());
    rt::Buffer host = memory.create(rt::Elem::F64, 6);
    std::vector<double> values = {0.5, 1.5, 2.5, 3.5, 4.5, 5.5};
    memory.write(host, 0, 6, values.data());
    rt::Buffer device = memory.create(rt::Elem::F64, 6);
    std::vector<uint32_t> all = {0, 1, 2, 3, 4, 5};
    memory.scatter(host, 0, device, all);
    REQUIRE(memory.onDevice(device));
    std::vector<uint32_t> rows = {5, rt::kSkipRow, 0, 0};
    rt::Buffer to = memory.create(rt::Elem::F64, 7);
    std::vector<double> before(7, -1);
    memory.write(to, 0, 7, before.data());
    uint64_t waits = memory.waits;
    memory.gather(device, to, 2, rows);
    CHECK(memory.waits == waits);
    CHECK(memory.onDevice(to));
    std::vector<double> out(7);
    memory.read(to, 0, 7, out.data());
    CHECK(out == std::vector<double>{-1, -1, 5.5, 0, 0.5, 0.5, -1});
    // Both on the host: gathered there.
    rt::Buffer onHost = memory.create(rt::Elem::F64, 4);
    memory.gather(host, onHost, 0, rows);
    CHECK_FALSE(memory.onDevice(onHost));
    memory.read(onHost, 0, 4, out.data());
    CHECK(std::vector<double>(out.begin(), out.begin() + 4) == std::vector<double>{5.5, 0, 0.5, 0.5});
}

TEST_CASE("clearing rows of a column on the GPU zeroes them there, without a read-back") {
    auto gpu = gpuBackend();
    auto& memory = static_cast<gpu::GlMemory&>(gpu->memory());
    rt::Buffer b = memory.create(rt::Elem::F32, 8);
    std::vector<float> values = {1, 2, 3, 4, 5, 6, 7, 8};
    memory.write(b, 0, 8, values.data());
    rt::Buffer moved = memory.create(rt::Elem::F32, 8);
    std::vector<uint32_t> rows = {0, 1, 2, 3, 4, 5, 6, 7};
    memory.scatter(b, 0, moved, rows);  // a scatter runs on the GPU: `moved` lives there now
    REQUIRE(memory.onDevice(moved));
    uint64_t waits = memory.waits;
    memory.clear(moved, 2, 3);
    CHECK(memory.waits == waits);
    CHECK(memory.onDevice(moved));
    memory.clear(b, 7, 1);  // on the host
    std::vector<float> out(8);
    memory.read(moved, 0, 8, out.data());
    CHECK(out == std::vector<float>{1, 2, 0, 0, 0, 6, 7, 8});
    memory.read(b, 0, 8, out.data());
    CHECK(out == std::vector<float>{1, 2, 3, 4, 5, 6, 7, 0});
    // A released column gives its GL buffer back (a later column reusing its slot may be
    // small).
    size_t held = memory.deviceBytes();
    memory.release(b);
    memory.release(moved);
    CHECK(memory.deviceBytes() < held);
    CHECK(memory.deviceBytes() == held - 2 * 8 * 4);
}

TEST_CASE("a kernel with more columns than storage blocks reads the rest through buffer textures") {
    // The fire's particles: their update writes 9 state columns and reads 6 parameters,
    // the creation times and the mask: 17 columns, 14 storage blocks. The 3 left over
    // are read in place through buffer textures, not copied through the launch's words
    // (12 bytes a particle a step).
    auto gpu = gpuBackend();
    rt::System system(test::compileModule(readFile(test::sample("fire"))), *gpu);
    auto part = static_cast<size_t>(system.typeIndex("part"));
    const ir::Object& o = system.module().objects[part];
    std::vector<int> direct = codegen_glsl::directColumns(*o.kernel(ir::KernelKind::Update),
                                                          rt::columnLayout(o, *o.kernel(ir::KernelKind::Update)));
    REQUIRE(direct.size() > codegen_glsl::kDirectSlots);
    for (int f = 0; f < 120; ++f) REQUIRE_FALSE(system.step(1.0 / 60));
    size_t live = system.pool(part).live();
    uint64_t staged = gpu->stagedBytes();
    for (int f = 0; f < 10; ++f) REQUIRE_FALSE(system.step(1.0 / 60));
    double perParticle = static_cast<double>(gpu->stagedBytes() - staged) / 10 / static_cast<double>(live);
    MESSAGE("bytes copied on the GPU per fire particle per step: " << perParticle);
    CHECK(perParticle < 2);
}

TEST_CASE("the rows killed are compacted on the GPU in row order, across work groups") {
    auto gpu = gpuBackend();  // a context
    gpu::Compactor compactor;
    uint32_t x = 12345;
    for (size_t n : {size_t{1}, size_t{255}, size_t{256}, size_t{257}, size_t{5000}, size_t{300'001}}) {
        for (uint32_t density : {0u, 3u, 50u, 100u}) {  // percent of rows set
            std::vector<uint32_t> flags(n);
            std::vector<uint32_t> expected;
            for (size_t i = 0; i < n; ++i) {
                x = x * 1664525u + 1013904223u;
                flags[i] = (x >> 8) % 100 < density ? 1u + (x & 7u) : 0u;
                if (flags[i]) expected.push_back(static_cast<uint32_t>(i));
            }
            INFO("n " << n << ", " << density << "% set");
            CHECK(compactor.flagged(flags) == expected);
        }
    }
}

TEST_CASE("the compaction zeroes a mask at the rows it lists, directly or through a list of rows") {
    // A late launch's kills cleared in its pool's alive mask: rows base + i of a pool's
    // update, or rows[offset + i] of a creation batch's.
    auto gpu = gpuBackend();  // a context
    gpu::Compactor compactor;
    uint32_t x = 777;
    for (size_t n : {size_t{1}, size_t{256}, size_t{1000}, size_t{70'001}}) {
        for (bool mapped : {false, true}) {
            const uint32_t base = 3, offset = 5;
            const size_t maskRows = n + 64;
            std::vector<uint32_t> flags(n), rows(n + offset), mask(maskRows, 1u), expected = mask;
            for (size_t i = 0; i < n + offset; ++i) rows[i] = static_cast<uint32_t>((i * 7919) % maskRows);
            for (size_t i = 0; i < n; ++i) {
                x = x * 1664525u + 1013904223u;
                flags[i] = (x >> 8) % 100 < 20 || (i >= 256 && i < 512) ? 1u : 0u;  // a whole group set too
                if (flags[i]) expected[mapped ? rows[offset + i] : base + i] = 0;
            }
            GLuint buffers[4] = {};
            glCreateBuffers(4, buffers);
            glNamedBufferData(buffers[0], static_cast<GLsizeiptr>(n * 4), flags.data(), GL_STATIC_DRAW);
            glNamedBufferData(buffers[1], static_cast<GLsizeiptr>((n + 1) * 4), nullptr, GL_DYNAMIC_READ);
            glNamedBufferData(buffers[2], static_cast<GLsizeiptr>(maskRows * 4), mask.data(), GL_DYNAMIC_COPY);
            glNamedBufferData(buffers[3], static_cast<GLsizeiptr>(rows.size() * 4), rows.data(), GL_STATIC_DRAW);
            gpu::Compactor::Clear clear{buffers[2], mapped ? buffers[3] : 0u, base, mapped ? offset : 0u};
            compactor.compact(buffers[0], 0, n, buffers[1], 0, &clear);
            glGetNamedBufferSubData(buffers[2], 0, static_cast<GLsizeiptr>(maskRows * 4), mask.data());
            glDeleteBuffers(4, buffers);
            INFO("n " << n << (mapped ? ", through rows" : ", directly"));
            CHECK(mask == expected);
        }
    }
}

TEST_CASE("what is drawn is computed and marked on the GPU, and stays there") {
    // A render pass reads which rows are alive from the host (4 bytes a row) and marks the
    // drawn rows itself; its 36 bytes of render columns a row stay on the GPU, where the
    // viewer draws from them.
    auto gpu = gpuBackend();
    rt::System system(test::compileModule(readFile(test::sample("fountain"))), *gpu);
    for (int f = 0; f < 60; ++f) REQUIRE_FALSE(system.step(1.0 / 60));
    auto drop = static_cast<size_t>(system.typeIndex("drop"));
    system.draw(drop);  // the first draw puts the render columns on the GPU
    REQUIRE_FALSE(system.step(1.0 / 60));
    uint64_t before = gpu->transferredBytes();
    const rt::DrawColumns& drawn = system.draw(drop);
    double perRow = static_cast<double>(gpu->transferredBytes() - before) / static_cast<double>(drawn.rows);
    MESSAGE("bytes between host and GPU per row drawn: " << perRow);
    CHECK(perRow <= 4.5);
    // The host did not wait for the count: it comes when the stats (or points) ask.
    CHECK_FALSE(drawn.counted);
    uint64_t waits = gpu->waits();
    system.stats();
    CHECK(drawn.counted);
    CHECK(drawn.drawn == system.pool(drop).live());
    CHECK(gpu->waits() == waits);
    CHECK(system.backend().memory().glBuffer(drawn.position[0]) != 0);
}


TEST_CASE("the GLSL backend refuses an op it has no code for with the located internal error every backend gives") {
    GpuBackend gpu = gpuBackend();
    CHECK(test::refusal(*gpu) == test::expectedRefusal("the GLSL backend"));
}
