// How many frames the tests that run every sample side by side run: 600 (10 s at 60 Hz),
// or 200 in the sanitizer build, where a frame costs ten times as much and what is looked
// for (memory errors, undefined behaviour) shows in the first frames.
#pragma once

namespace psys::test {

#ifdef PSYS_SANITIZED
constexpr int kLongRun = 200;
#else
constexpr int kLongRun = 600;
#endif

}  // namespace psys::test
