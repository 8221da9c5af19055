// What llvmpipe hides and a GPU shows: the barrier rule (gpu/hazards.h), strict mode,
// the GL's debug output, IEEE 754 where GLSL leaves results undefined, and grids past
// 65,535 work groups.
#include <doctest/doctest.h>

#include <epoxy/gl.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>

#include "gpu/hazards.h"
#include "gpu_support.h"

using namespace psys;
using namespace psys::test;

TEST_CASE("a shader's writes are made visible to each later reader by that reader's barrier bit") {
    using gpu::Write;
    // docs/gpu.md's table, row by row.
    CHECK(gpu::barrierBits(Write::Dispatch, gpu::kStorageBlock) == GL_SHADER_STORAGE_BARRIER_BIT);
    CHECK(gpu::barrierBits(Write::Dispatch, gpu::kBufferTexture) == GL_TEXTURE_FETCH_BARRIER_BIT);
    CHECK(gpu::barrierBits(Write::Dispatch, gpu::kUniformBlock) == GL_UNIFORM_BARRIER_BIT);
    CHECK(gpu::barrierBits(Write::Dispatch, gpu::kVertexPull) == GL_VERTEX_ATTRIB_ARRAY_BARRIER_BIT);
    CHECK(gpu::barrierBits(Write::Dispatch, gpu::kCopy) == GL_BUFFER_UPDATE_BARRIER_BIT);
    // A column written by a kernel may be read in place, through a texture, copied into a
    // launch block, read back or drawn: every one of those bits.
    CHECK(gpu::barrierBits(Write::Dispatch, gpu::kColumnReaders) ==
          (GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_UNIFORM_BARRIER_BIT |
           GL_VERTEX_ATTRIB_ARRAY_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT));
    // The GL orders its own commands: a copy, an upload or a clear needs no barrier, and
    // the host reads through the GL too.
    for (Write w : {Write::Copy, Write::Upload, Write::Clear}) CHECK(gpu::barrierBits(w, gpu::kColumnReaders) == 0);
}

TEST_CASE("in strict mode every write is followed by a full barrier and a wait, and nothing changes") {
    // What a GPU test that fails without strict mode and passes with it points at: a
    // missing barrier. Here both must pass, and give the same points.
    std::string text = readFile(test::sample("fireworks"));
    test::Comparison plain = compareProgram(text, 120, true, kSamplesTolerance);
    gpu::setStrictMode(true);
    test::Comparison strict = compareProgram(text, 120, true, kSamplesTolerance);
    gpu::setStrictMode(false);
    CHECK(strict.points == plain.points);
    CHECK(strict.worst == plain.worst);
}

TEST_CASE("the GL's debug output reaches the tests: an error is counted with its message") {
    // gpuBackend's deleter fails a test during which this count grows; here it must grow.
    gpu::requestDebugOutput(true);
    std::string error;
    auto gpu = gpu::GlslBackend::create(error);
    REQUIRE(gpu);
    uint64_t before = gpu::glErrorMessages();
    GLint bindings = 0;
    glGetIntegerv(GL_MAX_SHADER_STORAGE_BUFFER_BINDINGS, &bindings);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, static_cast<GLuint>(bindings) + 7, 0);  // GL_INVALID_VALUE
    CHECK(glGetError() == GL_INVALID_VALUE);
    CHECK(gpu::glErrorMessages() == before + 1);
    CHECK_FALSE(gpu::lastGlErrorMessage().empty());
    MESSAGE("the GL said: " << gpu::lastGlErrorMessage());
}

TEST_CASE("IEEE 754 where GLSL leaves it open: x / 0, mod(x, 0), 0 · NaN as the interpreter computes them") {
    // (age + 1) / (0 · age) is +∞, so the kill fires at once; a GL whose division refines a
    // reciprocal gives NaN and kills nothing. 0 · NaN is NaN even where a compiler folds
    // x · 0 to 0 (the kernels' zeros are opaque to it).
    Pair p(R"(
        object o(k: float) {
            z = 0 * age;
            q = (age + 1) / z;
            nq = k / -z;
            m = mod(age + 1, z);
            n = z * sqrt(z - 1);
            point(vec3(1, 2, 3), vec4(q > 1e30 ? 1 : 0, nq < -1e30 ? 1 : 0, m < 1e30 ? 0 : 1, n < 1e30 ? 0 : 1), 1);
            kill when q > 1000 && age > 0.05;
        }
        spawn o(1);
        spawn o(-2);)");
    for (int f = 0; f < 6; ++f) {
        p.steps(1, 1.0 / 60);
        auto points = p.gl->points(0);
        for (const rt::RenderPoint& point : points) {
            CHECK(point.color[0] == 1);
            CHECK(point.color[1] == (point.id == 0 ? 1 : 0));  // 1 / -0 is -∞, -2 / -0 is +∞
            CHECK(point.color[2] == 1);
            CHECK(point.color[3] == 1);
        }
        p.compare();
    }
    CHECK(p.stats("o").killed == 2);
}

TEST_CASE("a pool past 65,535 work groups of 64 rows (4,194,240) is created, updated and killed on the GPU") {
    // Scatters, gathers and the clearing of killed rows spread their grids over x and y as
    // the kernels do; one row more than a 1-D grid holds.
    const size_t n = size_t{65535} * 64 + 1;
    Pair p("@capacity(" + std::to_string(n) + ") object s { point(origin, white, 1); kill when age > 0.05; }\n" +
           "trigger boom { emit s count " + std::to_string(n) + "; }");
    p.fire("boom");
    p.steps(1, 1.0 / 60);
    p.gl->finish();
    CHECK(p.stats("s").live == n);
    CHECK(p.gl->draw(0).rows == n);
    p.steps(4, 1.0 / 60);
    p.gl->finish();
    CHECK(p.stats("s").killed == n);
    CHECK(p.stats("s").live == 0);
    CHECK(p.gl->points(0).empty());
    CHECK(p.cpu->stats().types[0].killed == n);
}

TEST_CASE("a burst chain creates an object at a time on the host side, its writes to the GPU sent together") {
    // Each object emits the next in its first update: ten thousand waves of one object in
    // the first step. A wave is a batch of one row: it runs on the host side, and what it
    // writes into the pool's rows on the GPU goes up with the others, not a dispatch for
    // each column of each object (a dispatch a column an object: 155 s for 30 frames at 100k,
    // against 1.4 s; docs/performance.md).
    const char* text = "@capacity(10000) object a { emit a; point(vec3(age, 0, 0), white, 1); kill when age > 0.5; }\n"
                       "spawn a;";
    Pair p(text, true, true);
    uint64_t before = p.gpu->dispatches();
    p.steps(1, 1.0 / 60);
    uint64_t dispatches = p.gpu->dispatches() - before;
    MESSAGE("dispatches for a chain of 10,000 waves: " << dispatches);
    CHECK(p.stats("a").created == 10000);
    CHECK(dispatches < 100);
    CHECK(p.gpu->hostLaunches() >= 10000);
    for (int f = 0; f < 40; ++f) {
        p.steps(1, 1.0 / 60);
        p.compare();
        REQUIRE(test::poolRows(*p.cpu) == test::poolRows(*p.gl));
    }
    CHECK(p.stats("a").killed == 10000);
}

TEST_CASE("the dispatches a step do not grow with the emitters when their children emit nothing") {
    // K sources, each emitting two types that emit nothing: the queue holds spark, puff,
    // spark, puff, … Each type is created in one batch a step (rt/system_queue.cpp,
    // Creation::groupByType) and each spawn kernel's launches go in one dispatch
    // (GlslBackend::runChildren) — the campfire's dispatches grew tenfold with its fires.
    // (36 dispatches a step for 4 sources and for 40; a batch an emitter made 40 and 432.)
    auto perStep = [](int sources) {
        std::string text = R"(
            object spark(p: vec3) { pos = snapshot(p) + integrate(vec3(0, -1, 0)); point(pos, white, 1); kill when age > 0.3; }
            object puff(x: float) { point(vec3(x, age, rand()), white, 1); kill when age > 0.25; }
            object source(x: float) {
                emit spark(vec3(x, rand(), 0)) at 150 per second;
                emit puff(x + rand()) at 70 per second;
            }
        )";
        for (int k = 0; k < sources; ++k) text += "spawn source(" + std::to_string(k) + ");\n";
        Pair p(text);  // (every launch on the GPU: no pool small enough for the host side)
        p.steps(30, 1.0 / 60);  // (the pools grown)
        uint64_t before = p.gpu->dispatches();
        p.steps(10, 1.0 / 60);
        double dispatches = static_cast<double>(p.gpu->dispatches() - before) / 10;
        p.compare();
        return dispatches;
    };
    double few = perStep(3), many = perStep(30);
    MESSAGE("dispatches a step: " << few << " with 3 sources, " << many << " with 30");
    CHECK(few == many);
}

TEST_CASE("many object types of a few objects each run on the host side: no dispatch a step") {
    // 100 types of one object: their updates (late or not) and draws run where their
    // columns are, on the host, as fast as the interpreter; a dispatch each would be 200
    // dispatches a step and more (400 types: 0.9 s for 600 frames on llvmpipe, 42 s with a
    // dispatch each; docs/performance.md).
    std::string text;
    for (int t = 0; t < 100; ++t)
        text += "object t" + std::to_string(t) + " { p = integrate(vec3(" + std::to_string(t) +
                ", 1, 0)); point(p, white, 1); kill when age > 1; }\nspawn t" + std::to_string(t) + ";\n";
    Pair p(text, true, true);
    p.steps(2, 1.0 / 60);
    uint64_t before = p.gpu->dispatches(), host = p.gpu->hostLaunches();
    for (int f = 0; f < 10; ++f) {
        p.steps(1, 1.0 / 60);
        for (size_t t = 0; t < p.gl->typeCount(); ++t) p.gl->draw(t);
        p.gl->stats();
    }
    CHECK(p.gpu->dispatches() == before);
    CHECK(p.gpu->hostLaunches() - host >= 100 * 2 * 10);
    for (int f = 0; f < 60; ++f) {
        p.steps(1, 1.0 / 60);
        if (f % 10 == 0) p.compare();
    }
    p.compare();
    CHECK(p.stats("t7").killed == 1);
}

TEST_CASE("programs are compiled in parallel where the driver can, and loaded from a disk cache where it gives binaries") {
    // The cache in a directory of the test's own; a second backend compiling the same
    // system's programs loads every one of them from it — where the driver gives program
    // binaries (llvmpipe gives none: there the backend compiles, and says so).
    auto dir = std::filesystem::temp_directory_path() / ("psys-gl-cache-" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    setenv("PSYS_GL_CACHE", dir.c_str(), 1);
    std::string text = readFile(test::sample("fireworks"));
    size_t kernels = 0;
    {
        auto first = gpuBackend();
        rt::System system(test::compileModule(text), *first);
        REQUIRE_FALSE(system.step(1.0 / 60));
        kernels = first->report().kernels;
        MESSAGE("the driver compiles in parallel: " << first->parallelCompile()
                << "; gives program binaries: " << first->programBinaries());
        CHECK(first->programsLoaded() == 0);
    }
    auto second = gpuBackend();
    rt::System system(test::compileModule(text), *second);
    REQUIRE_FALSE(system.step(1.0 / 60));
    if (second->programBinaries())
        CHECK(second->programsLoaded() == kernels);
    else
        CHECK(second->programsLoaded() == 0);
    unsetenv("PSYS_GL_CACHE");
    std::filesystem::remove_all(dir);
}

TEST_CASE("what a draw counts is read back after the copy that carries it: the fluid's pool grows, every frame drawn") {
    // The host reads the read-back buffer through the GL (gpu/glsl_readback.cpp): on zink
    // a fence after the copy of a draw's counts passed before the copy had run, and a
    // mapped read took 0 for the 132 drops of the step their columns grew past 128 rows.
    // Each frame's points are asked for at once, as a host that draws every step asks.
    test::Comparison c = compareProgram(readFile(test::sample("fluid")), 40, true, kSamplesTolerance);
    CHECK(c.points > 0);
}
