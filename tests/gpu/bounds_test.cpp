// The box around what is drawn (rt::System::bounds), reduced on the GPU where the draw
// columns are: the same box as the points it draws, within the samples' tolerance of the
// interpreter's, and only 24 bytes to the host.
#include <doctest/doctest.h>

#include <algorithm>
#include <limits>

#include "gpu_support.h"
#include "tests/run_length.h"

using namespace psys;
using namespace psys::test;

namespace {

// The box around a system's drawn points, from the points read back.
rt::Bounds boxOf(const std::vector<rt::RenderPoint>& points) {
    rt::Bounds b;
    b.low.fill(std::numeric_limits<float>::infinity());
    b.high.fill(-std::numeric_limits<float>::infinity());
    for (const auto& p : points)
        for (size_t c = 0; c < 3; ++c) {
            b.low[c] = std::min(b.low[c], p.position[c]);
            b.high[c] = std::max(b.high[c], p.position[c]);
        }
    b.empty = points.empty();
    if (b.empty) b = {};
    return b;
}

}  // namespace

TEST_CASE("every sample's box on the GPU is its drawn points' box, the interpreter's within tolerance, 24 bytes back") {
    size_t boxes = 0, onGpu = 0;
    for (const auto& path : test::sweptSamples()) {
        INFO(path.filename().string());
        Pair p(readFile(path));
        p.steps(std::min(120, test::closeFrames(p.gl->module())), 1.0 / 60);  // (a crowd: its first frames)
        for (size_t t = 0; t < p.gl->typeCount(); ++t) {
            INFO("type " << p.gl->module().objects[t].name);
            auto& gl = dynamic_cast<gpu::GlslBackend&>(p.gl->backend());
            p.gl->draw(t);
            uint64_t waits = gl.waits(), moved = gl.transferredBytes();
            rt::Bounds box = p.gl->bounds(t);
            uint64_t waited = gl.waits() - waits, sent = gl.transferredBytes() - moved;
            CHECK(box == boxOf(p.gl->points(t)));
            rt::Bounds cpu = p.cpu->bounds(t);
            CHECK(cpu.empty == box.empty);
            if (box.empty) continue;
            ++boxes;
            CHECK(waited <= 1);
            onGpu += waited == 1;  // (else its columns were on the host: reduced there)
            CHECK(sent <= 48);
            for (size_t c = 0; c < 3; ++c) {
                CHECK(std::abs(box.low[c] - cpu.low[c]) <= kSamplesTolerance * std::max(1.0f, std::abs(cpu.low[c])));
                CHECK(std::abs(box.high[c] - cpu.high[c]) <= kSamplesTolerance * std::max(1.0f, std::abs(cpu.high[c])));
            }
        }
    }
    MESSAGE(boxes << " boxes, " << onGpu << " reduced on the GPU");
    CHECK(boxes > (test::onSecondGl() ? 4u : 20u));
    CHECK(onGpu > (test::onSecondGl() ? 1u : 10u));
}
