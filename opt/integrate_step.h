// An object's integrals as one derivative system y' = f(age, y), and the tool every
// integration method but the default is built with (opt/lower_temporal.cpp uses it).
//
// The input is the behaviour after lower-temporal's first phase: `prev`, `snapshot`,
// `derive` and `->` are state reads and selects already, but every integral is still an
// `integrate` instruction whose operand is its derivative, and `recur` (a reference to an
// equation evaluated later, kept by resolve-cycles where the cycle runs through an
// integral) still closes the cycles. A StepBuilder rebuilds that kernel in order:
//
//   - `final(v)`: v at the end of the update, once every integral has its new value (the
//     method's result); a `recur` is its equation's final value;
//   - `at(point, v)`: v re-evaluated at a point inside the step (a Runge–Kutta stage):
//     the integrals at the point's values, `age` and `time` at the point's instant, every
//     value that depends on them re-evaluated; everything else — parameters, externs,
//     random draws, `prev` and `snapshot`, parent reads — is the update's one value.
//
// The method itself is a function that, given the builder, returns each integral's value
// at the end of the update (opt/integrate_methods.cpp, opt/integrate_exact.cpp).
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <set>
#include <vector>

#include "ir/ir.h"

namespace psys::opt {

class StepBuilder {
public:
    // `from`: the first-phase kernel; `integrals`: its `integrate` instructions, in order,
    // and the state slot each keeps its value in.
    StepBuilder(const ir::Kernel& from, std::vector<ir::ValueId> integrals, std::vector<int> slots);

    // An instant inside the update: the integrals' values there, and its place in the
    // step (the age and time there are built when a derivative reads them).
    struct Point {
        std::vector<ir::ValueId> y;
        float c = 0;  // 0: the start of the step, 1: its end
        std::map<ir::ValueId, ir::ValueId> values;  // what `at` built for it
        // Where set, the instant instead of c: seconds since the update's start (an
        // adaptive method's stages lie where its own steps put them).
        std::optional<ir::ValueId> since;
    };

    // The system.
    size_t size() const { return integrals_.size(); }
    ir::ValueId integral(size_t j) const { return integrals_[j]; }
    ir::ValueId derivative(size_t j) const { return from_.at(integrals_[j]).operands[0]; }
    ir::Type type(size_t j) const { return from_.at(integrals_[j]).type; }
    ir::Loc loc(size_t j) const { return from_.at(integrals_[j]).loc; }
    const ir::Kernel& from() const { return from_; }
    // Whether a value of the first-phase kernel changes within the step: it depends on an
    // integral, the age or the time.
    bool dependent(ir::ValueId old) const { return dependent_[old]; }
    // What a `recur` stands for.
    ir::ValueId resolve(ir::ValueId old) const;
    // The integrals integral j's derivative reads at the same instant (through equations
    // and `recur`, not through another integral's derivative).
    std::set<size_t> reads(size_t j) const;

    // Building the new kernel.
    ir::Kernel& to() { return to_; }
    ir::ValueId dt();
    ir::ValueId start(size_t j);  // integral j before the update: its state slot
    // The point at fraction c of the step (0: its start, 1: its end) with integrals `y`.
    Point pointAt(float c, std::vector<ir::ValueId> y) { return {std::move(y), c, {}, std::nullopt}; }
    // The point `since` seconds (a value of the new kernel) after the update's start.
    Point pointSince(ir::ValueId since, std::vector<ir::ValueId> y) { return {std::move(y), 0, {}, since}; }
    Point& startPoint();          // c = 0, every integral at its start value
    // The age or the time at a point.
    ir::ValueId clockAt(ir::Op input, const Point& point);
    ir::ValueId at(Point& point, ir::ValueId old);
    ir::ValueId final(ir::ValueId old);
    // Stages see `old` as `seen` instead of re-evaluating it (a `derive`: its value at the
    // last update).
    void stageView(ir::ValueId old, ir::ValueId seen) { stageViews_[old] = seen; }
    // Whether `old` is fixed when the object is created: built from constants and
    // parameters, or a `snapshot` of such (lowered to a state read, whose value is the
    // same bits: with or without the optimizer, which folds it away, the same answer).
    void snapshotOfFixed(ir::ValueId old) { snapshotsOfFixed_.insert(old); }
    bool fixedAtCreation(ir::ValueId old) const;

    // Builds the kernel: every yield and equation at its final value; `solve` gives each
    // integral's value at the end of the update (called once, when first needed).
    using Solve = std::function<std::vector<ir::ValueId>(StepBuilder&)>;
    void run(const Solve& solve);
    ir::Kernel take();

    // Arithmetic on the new kernel.
    ir::ValueId add(ir::ValueId a, ir::ValueId b);
    ir::ValueId mul(ir::ValueId a, ir::ValueId b);  // a scalar times a vector is splat first
    ir::ValueId scalar(float x) { return to_.scalar(x); }

private:
    ir::ValueId copy(ir::ValueId old, const std::function<ir::ValueId(ir::ValueId)>& operand);

    const ir::Kernel& from_;
    std::vector<ir::ValueId> integrals_;
    std::vector<int> slots_;
    std::map<ir::ValueId, size_t> integralIndex_;
    std::vector<bool> dependent_;
    std::map<ir::ValueId, ir::ValueId> stageViews_;
    std::set<ir::ValueId> snapshotsOfFixed_;
    ir::Kernel to_;
    std::map<ir::ValueId, ir::ValueId> final_;
    std::vector<ir::ValueId> solved_;
    const Solve* solve_ = nullptr;
    bool solving_ = false;
    std::vector<Point> start_;
};

}  // namespace psys::opt
