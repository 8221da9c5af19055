// How many frames the tests that run every sample side by side run: 600 (10 s at 60 Hz),
// or 200 in the sanitizer build, where a frame costs ten times as much and what is looked
// for (memory errors, undefined behaviour) shows in the first frames.
#pragma once

#include <climits>

#include "ir/ir.h"

namespace psys::test {

#ifdef PSYS_SANITIZED
constexpr int kLongRun = 200;
#else
constexpr int kLongRun = 600;
#endif

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
