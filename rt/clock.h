// Time keeping: what time it is for each row of a launch, and the one rule for an
// object's age.
//
// The run-time decides every row's time; a backend only reads it. A launch's Clock says
// where `now` (the time the rows are evaluated at) and `dt` (the length of the update)
// come from: one value for every row, or a column with a value per row:
//   a step of existing objects      now = the step's end, dt = its length (both uniform)
//   objects being created (init)    now = each one's creation time (the created column),
//                                   dt = 0 (uniform), first = true; their exports at
//                                   creation the same, dt a column of zeros
//   their first, partial update     now = the step's end, dt = now − created, per row:
//                                   the row's age at now, computed where the row is
//                                   (SinceCreated: no column for it)
//   sub-steps of new objects        now and dt per row (columns the run-time fills)
// and age is always `ageAt(now, created)`. `time` in equations is float(now).
#pragma once

#include <cmath>
#include <cstdint>

namespace psys::rt {

struct Clock {
    enum class Source : uint8_t {
        Uniform,  // the value below, for every row
        PerRow,   // the launch's column (ColumnLayout::kNow: f64, kDt: f32)
        // dt only: the row's age at now, ageAt(now, created) — the length of an update
        // from the row's creation to now, as a first update is.
        SinceCreated,
    };
    Source now = Source::Uniform, dt = Source::Uniform;
    double nowValue = 0;
    float dtValue = 0;
    bool first = false;  // the rows are being created

    // Whether some row's clock differs from another's.
    static bool perRow(Source now, Source dt) { return now != Source::Uniform || dt != Source::Uniform; }
    bool perRow() const { return perRow(now, dt); }
};

// An object's age at `now`: the difference of two doubles, rounded to float once, so that
// after 10^7 s of running an age is still exact to well under a millisecond. Written over
// an algebra (as core/hash.h is) so that each backend emits this rule rather than
// restating it: A provides `Float narrow(Double)` and `Double minus(Double, Double)`.
template <class A>
typename A::Float ageAt(A& a, typename A::Double now, typename A::Double created) {
    return a.narrow(a.minus(now, created));
}

struct HostTimeAlgebra {
    using Double = double;
    using Float = float;
    static double minus(double a, double b) { return a - b; }
    static float narrow(double x) { return static_cast<float>(x); }
};

inline float ageAt(double now, double created) {
    HostTimeAlgebra a;
    return ageAt(a, now, created);
}

// Sub-steps (@step(h)): an update over (t1 − span, t1] in equal sub-steps of at most h
// seconds, the same rule for a pool's step (System::runPhases) and for each new object's
// first update (Creation, and Memory::subStepClocks where the rows are).
// The most sub-steps one update of an object takes under @step(h): a 10 s hitch at
// @step(1/240) is 2,400; `@step(1e-30)` or a step of 1e30 s would never end. Past it the
// update takes kMaxSubSteps longer sub-steps, and the type's stats count it.
constexpr uint32_t kMaxSubSteps = 10000;

// Sub-steps of at most `h` seconds covering `span` (h <= 0: one), capped and counted.
inline uint32_t subStepCount(double span, double h, uint64_t& capped) {
    if (!(h > 0) || !(span > h)) return 1;
    double n = std::ceil(span / h);
    if (n > kMaxSubSteps) {
        ++capped;
        return kMaxSubSteps;
    }
    return static_cast<uint32_t>(n);
}

// The end of sub-step k (from 1) of `steps`: t1 itself for the last.
inline double subStepEnd(double t1, double span, uint32_t k, uint32_t steps) {
    return k == steps ? t1 : (t1 - span) + span * (static_cast<double>(k) / steps);
}

}  // namespace psys::rt
