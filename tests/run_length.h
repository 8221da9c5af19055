// How many frames the tests that run every sample side by side run: 600 (10 s at 60 Hz),
// or 200 in the sanitizer build, where a frame costs ten times as much and what is looked
// for (memory errors, undefined behaviour) shows in the first frames.
//
// A test that runs longer in the release build than under the sanitizers (a 600-frame
// sweep), or only there (kSanitized below), is in the doctest suite `long`
// (`TEST_CASE("…" * doctest::test_suite("long"))`), which scripts/test.sh's release stage
// runs (it lists the suite from each test binary: `psys_unit_tests --test-suite=long
// --list-test-cases`).
// Every other test the sanitizer build registers runs there only, in CI: the same code on
// the same inputs, with memory errors and undefined behaviour caught.
#pragma once

#include <climits>
#include <cstdlib>

#include "ir/ir.h"

namespace psys::test {

#ifdef PSYS_SANITIZED
constexpr int kLongRun = 200;
// A test of numbers alone — a long integration's error, taking no path of the run-time
// the other tests do not — is skipped under the sanitizers (`TEST_CASE("…" *
// doctest::skip(test::kSanitized))`): it runs in the release build.
constexpr bool kSanitized = true;
#else
constexpr int kLongRun = 600;
constexpr bool kSanitized = false;
#endif

// How many frames a test over every sample and test program that looks at the step's
// bookkeeping (kills, rows, draws) runs: `frames` in the release build, half of them under
// the sanitizers — a frame there costs ten times as much, and the paths a run takes (each
// kind of creation, death, trigger) show in the first half; such a test is in the suite
// `long` (above), so the release stage runs it whole.
inline int bookkeepingFrames(int frames) { return kSanitized ? frames / 2 : frames; }

// The GPU suite runs three times: on llvmpipe, then in strict mode and on zink
// (tests/gpu/CMakeLists.txt), which look for a missing barrier or work done out of order —
// what shows in a sample's first frames. Those two set PSYS_TEST_FRAMES (120): the long
// runs are llvmpipe's.
inline int longRun() {
    static const int frames = [] {
        const char* v = std::getenv("PSYS_TEST_FRAMES");
        int n = v ? std::atoi(v) : 0;
        return n > 0 ? n : kLongRun;
    }();
    return frames;
}

// A crowd — objects that fold over their neighbours (docs/language.md, "Neighbours") — is
// chaotic: a difference in a last bit moves an object, which changes its neighbours'
// pushes, step after step, growing from step to step. Backends that round
// differently (fast maths, the GPU) are compared object by object over a crowd's first
// kCrowdRun frames; after that, by what is alive (the same objects in the same rows).
// Backends that round alike (the JIT in exact maths) agree bit for bit over every frame.
constexpr int kCrowdRun = 20;
inline int closeFrames(const ir::Module& m) {
    for (const ir::Object& o : m.objects)
        if (!o.folds.empty()) return kCrowdRun;
    return INT_MAX;
}

}  // namespace psys::test
