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

}  // namespace psys::rt
