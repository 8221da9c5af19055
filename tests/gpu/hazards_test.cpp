// What llvmpipe hides and a GPU shows: the barrier rule (gpu/hazards.h), strict mode,
// the GL's debug output, IEEE 754 where GLSL leaves results undefined, and grids past
// 65,535 work groups.
#include <doctest/doctest.h>

#include <epoxy/gl.h>

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
    CHECK(gpu::barrierBits(Write::Dispatch, gpu::kHostMap) == GL_CLIENT_MAPPED_BUFFER_BARRIER_BIT);
    // A column written by a kernel may be read in place, through a texture, copied into a
    // launch block, read back or drawn: every one of those bits.
    CHECK(gpu::barrierBits(Write::Dispatch, gpu::kColumnReaders) ==
          (GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_UNIFORM_BARRIER_BIT |
           GL_VERTEX_ATTRIB_ARRAY_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT));
    // The GL orders its own commands: a copy, an upload or a clear needs no barrier (a host
    // map still waits for a fence).
    for (Write w : {Write::Copy, Write::Upload, Write::Clear})
        CHECK(gpu::barrierBits(w, gpu::kColumnReaders | gpu::kHostMap) == 0);
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
