// Two systems of one program on two backends, run side by side: the backends' differential
// tests (tests/llvm, tests/gpu). They must create, kill and draw the same objects, with
// the same ids, frame after frame; how far their values may differ is each test's
// tolerance, argued where it is set.
#pragma once

#include <climits>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "rt/system.h"

namespace psys::test {

inline bool samePoint(const rt::RenderPoint& a, const rt::RenderPoint& b) {
    return a.id == b.id && std::memcmp(&a.position, &b.position, sizeof a.position) == 0 &&
           std::memcmp(&a.color, &b.color, sizeof a.color) == 0 && std::memcmp(&a.size, &b.size, sizeof a.size) == 0 &&
           std::memcmp(&a.rotation, &b.rotation, sizeof a.rotation) == 0 &&
           std::memcmp(&a.frame, &b.frame, sizeof a.frame) == 0 && std::memcmp(&a.end, &b.end, sizeof a.end) == 0;
}

// The largest difference between two points' values, relative to max(1, |value|); a NaN
// on one side only counts as 1e9.
inline double pointDifference(const rt::RenderPoint& a, const rt::RenderPoint& b) {
    double worst = 0;
    auto compare = [&worst](float x, float y) {
        double d = std::fabs(double(x) - double(y)) / std::max(1.0, std::fabs(double(x)));
        worst = std::max(worst, std::isnan(d) ? (std::isnan(x) && std::isnan(y) ? 0.0 : 1e9) : d);
    };
    for (size_t i = 0; i < 3; ++i) compare(a.position[i], b.position[i]);
    for (size_t i = 0; i < 4; ++i) compare(a.color[i], b.color[i]);
    compare(a.size, b.size);
    compare(a.rotation, b.rotation);
    compare(a.frame, b.frame);
    for (size_t i = 0; i < 3; ++i) compare(a.end[i], b.end[i]);
    return worst;
}

struct Comparison {
    size_t points = 0;       // drawn points compared, over every frame
    size_t differences = 0;  // of them, those not equal bit for bit
    double worst = 0;        // the largest pointDifference
};

// The same objects in the same rows: every pool's rows, their status and generations,
// and its free stack (the allocation rule, rt/allocation.h, on both sides).
inline bool sameRows(const rt::System& a, const rt::System& b) {
    for (size_t t = 0; t < a.typeCount(); ++t) {
        const rt::Pool &pa = a.pool(t), &pb = b.pool(t);
        INFO("type " << a.module().objects[t].name);
        if (pa.rows() != pb.rows() || pa.generations() != pb.generations() || pa.freeRows() != pb.freeRows()) return false;
        for (uint32_t row = 0; row < pa.rows(); ++row)
            if (pa.status(row) != pb.status(row)) return false;
    }
    return true;
}

// Fires every trigger of both systems (each argument 1.5).
inline void fireEveryTrigger(rt::System& a, rt::System& b) {
    for (const ir::Trigger& t : a.module().triggers) {
        size_t width = 0;
        for (auto& p : t.params) width += static_cast<size_t>(p.type.width);
        std::vector<float> args(width, 1.5f);
        REQUIRE_FALSE(a.fire(t.name, args));
        REQUIRE_FALSE(b.fire(t.name, args));
    }
}

// Steps both systems `frames` times by 1/60 s, firing every trigger before step
// `fireAt` (0: before the first; mid-run, the trigger's objects meet a step's deaths),
// comparing what is drawn after each step and the counts at the end.
// Values are compared over the first `closeFrames` frames (test::closeFrames: a crowd's
// first ones), what is alive over all of them.
inline Comparison compareSystems(rt::System& a, rt::System& b, int frames, int closeFrames = INT_MAX, int fireAt = 0) {
    Comparison result;
    for (int frame = 0; frame < frames; ++frame) {
        if (frame == fireAt) fireEveryTrigger(a, b);
        REQUIRE_FALSE(a.step(1.0 / 60));
        REQUIRE_FALSE(b.step(1.0 / 60));
        for (size_t t = 0; t < a.typeCount(); ++t) {
            const auto& pa = a.points(t);
            const auto& pb = b.points(t);
            INFO("frame " << frame << ", type " << a.module().objects[t].name);
            REQUIRE(pa.size() == pb.size());
            for (size_t i = 0; i < pa.size(); ++i) {
                REQUIRE(pa[i].id == pb[i].id);
                if (frame >= closeFrames) continue;
                result.differences += samePoint(pa[i], pb[i]) ? 0 : 1;
                result.worst = std::max(result.worst, pointDifference(pa[i], pb[i]));
            }
            if (frame < closeFrames) result.points += pa.size();
        }
    }
    a.finish();  // what a device still owes from the last step
    b.finish();
    CHECK(sameRows(a, b));
    CHECK(a.stats().types.size() == b.stats().types.size());
    for (size_t t = 0; t < a.stats().types.size(); ++t) {
        CHECK(a.stats().types[t].created == b.stats().types[t].created);
        CHECK(a.stats().types[t].killed == b.stats().types[t].killed);
        CHECK(a.stats().types[t].dropped == b.stats().types[t].dropped);
        CHECK(a.stats().types[t].unstable == b.stats().types[t].unstable);
    }
    return result;
}

}  // namespace psys::test
