// bs3: the Bogacki–Shampine 3(2) embedded pair, each object taking steps of its own length
// under error control.
//
// Why inside the update kernel, unrolled: every backend runs an update as one kernel over
// the rows, without loops, and an object's steps must be its own (one particle in a stiff
// drag, its neighbour in free flight). So an update holds kAttempts attempts, one after the
// other; in each, every object tries a step from where it got to, and a select keeps the
// step where its error estimate is within bounds (a rejected attempt leaves the object
// where it was, with a shorter step to try). The last attempt takes what is left of the
// update, whatever its error, so that every object ends the update at its end; where that
// error is past the bound, the update is counted as beyond what the method holds (the
// `unstable` yield and stats). A finer @step gives an object more attempts a frame. The
// length to try next is state (slot `bs3@step`), carried from update to update: 0 at
// creation, read as "the whole update".
//
// One step of length h from (s, y), s the seconds since the update's start, k1 = f(s, y):
//   k2 = f(s + h/2, y + h/2·k1)      k3 = f(s + 3h/4, y + 3h/4·k2)
//   y' = y + h·(2/9·k1 + 1/3·k2 + 4/9·k3)                         (order 3)
//   k4 = f(s + h, y')                 the next step's k1 where this one is kept (FSAL)
//   e  = h·(−5/72·k1 + 1/12·k2 + 1/9·k3 − 1/8·k4)                  (y' less the order-2 answer)
// Error per unit step: a step is kept while |e| ≤ r·h for every integral (a vector's
// length), r the tolerance per second — the object's @tolerance(metres, seconds) as
// metres / seconds, else core::kBs3Tolerance over core::kToleranceSeconds — so the local errors let through add up to at
// most the tolerance over its time. Since e/(r·h) grows as h², the next step is h times the
// power of two nearest 0.9·(|e|/(r·h))^(−1/2), from 1/16 to 4: comparisons alone, no library
// function, the same decision on every backend. A kept step that was cut short by the
// update's end does not shorten the next.
#include <optional>

#include "opt/integrate_methods.h"

namespace psys::opt {

using namespace ir;

namespace {

constexpr int kAttempts = 4;

// |e| ≤ ratio·r·h, squared on both sides: e·e ≤ ratio²·(r·h)².
struct Bounds {
    Kernel& k;
    ValueId err2, allowed2;
    ValueId within(float ratio) {
        return k.op(Op::Le, Type::boolean(), {err2, k.op(Op::Mul, Type::f32(), {k.scalar(ratio * ratio), allowed2})});
    }
};

}  // namespace

std::vector<ValueId> bogackiShampine(StepBuilder& b, int stepSlot, float tolerancePerSecond, bool exactWeights) {
    Kernel& k = b.to();
    size_t n = b.size();
    const Type f32 = Type::f32(), boolean = Type::boolean();
    auto select = [&](ValueId c, ValueId x, ValueId y) { return k.op(Op::Select, k.at(x).type, {c, x, y}); };
    auto sub = [&](ValueId x, ValueId y) { return k.op(Op::Sub, f32, {x, y}); };
    // h·Σ w_i·k_i[j], integral j's share of a step (terms of weight 0 left out).
    using Slopes = std::vector<ValueId>;
    auto weighted = [&](ValueId h, std::initializer_list<std::pair<float, const Slopes*>> terms, size_t j) {
        ValueId sum = 0;
        bool any = false;
        for (auto [w, slopes] : terms) {
            if (w == 0) continue;
            ValueId term = b.mul(b.scalar(w), (*slopes)[j]);
            sum = any ? b.add(sum, term) : term;
            any = true;
        }
        return b.mul(h, sum);
    };

    ValueId dt = b.dt(), zero = b.scalar(0);
    ValueId since = zero;
    std::optional<ValueId> missed;  // the last try kept a step past the bounds
    ValueId h = k.add(Inst::make(Op::StateRead, f32, {}, stepSlot));
    StepBuilder::Point& start = b.startPoint();
    Slopes y = start.y, k1;
    for (size_t j = 0; j < n; ++j) k1.push_back(b.at(start, b.derivative(j)));

    for (int attempt = 0; attempt < kAttempts; ++attempt) {
        bool last = attempt == kAttempts - 1;
        ValueId rest = sub(dt, since);
        ValueId live = k.op(Op::Gt, boolean, {rest, zero});
        ValueId tried = last ? rest
                             : select(k.op(Op::Gt, boolean, {h, zero}), k.op(Op::Min, f32, {h, rest}), rest);
        auto instant = [&](float c) { return b.add(since, c == 1 ? tried : b.mul(b.scalar(c), tried)); };
        Slopes y2, k2, y3, k3, y4, k4;
        for (size_t j = 0; j < n; ++j) y2.push_back(b.add(y[j], weighted(tried, {{0.5f, &k1}}, j)));
        StepBuilder::Point p2 = b.pointSince(instant(0.5f), y2);
        for (size_t j = 0; j < n; ++j) k2.push_back(b.at(p2, b.derivative(j)));
        for (size_t j = 0; j < n; ++j) y3.push_back(b.add(y[j], weighted(tried, {{0.75f, &k2}}, j)));
        StepBuilder::Point p3 = b.pointSince(instant(0.75f), y3);
        for (size_t j = 0; j < n; ++j) k3.push_back(b.at(p3, b.derivative(j)));
        for (size_t j = 0; j < n; ++j) {
            if (!exactWeights) {
                y4.push_back(b.add(y[j], weighted(tried, {{2.0f / 9, &k1}, {1.0f / 3, &k2}, {4.0f / 9, &k3}}, j)));
                continue;
            }
            // Under @precision(double): (2·k1 + 3·k2 + 4·k3)/9, divided in pairs (the
            // double-precision pass), where 2/9 as a float would be off by 1e-8.
            ValueId step = weighted(tried, {{2, &k1}, {3, &k2}, {4, &k3}}, j);
            Type t = k.at(step).type;
            y4.push_back(b.add(y[j], k.op(Op::Div, t, {step, k.constant(t, {9, 9, 9, 9})})));
        }
        StepBuilder::Point p4 = b.pointSince(instant(1), y4);
        for (size_t j = 0; j < n; ++j) k4.push_back(b.at(p4, b.derivative(j)));

        // The largest squared error over the integrals.
        ValueId err2 = 0;
        for (size_t j = 0; j < n; ++j) {
            LocScope at(k, b.loc(j));
            ValueId e = weighted(tried, {{-5.0f / 72, &k1}, {1.0f / 12, &k2}, {1.0f / 9, &k3}, {-1.0f / 8, &k4}}, j);
            ValueId sq = k.at(e).type.width > 1 ? k.op(Op::Dot, f32, {e, e}) : k.op(Op::Mul, f32, {e, e});
            err2 = j == 0 ? sq : k.op(Op::Max, f32, {err2, sq});
        }
        ValueId allowed = b.mul(b.scalar(tolerancePerSecond), tried);
        Bounds bounds{k, err2, k.op(Op::Mul, f32, {allowed, allowed})};
        ValueId within = bounds.within(1);
        ValueId keep = last ? live : k.op(Op::And, boolean, {live, within});
        if (last) missed = k.op(Op::And, boolean, {live, k.op(Op::Not, boolean, {within})});
        // 0.9·q^(−1/2) nearest 4, 2, 1, ½, ¼, ⅛ at q = 0.101, 0.405, 1.62 (1 for a kept step),
        // 6.48, 25.9, 104; else 1/16 (a first try over the whole update is often far off).
        ValueId factor = b.scalar(1.0f / 16);
        for (auto [q, f] : {std::pair{104.0f, 0.125f}, {25.9f, 0.25f}, {6.48f, 0.5f}})
            factor = select(bounds.within(q), b.scalar(f), factor);
        factor = select(within, b.scalar(1), factor);
        factor = select(bounds.within(0.405f), b.scalar(2), factor);
        factor = select(bounds.within(0.101f), b.scalar(4), factor);
        ValueId next = b.mul(tried, factor);
        next = select(within, k.op(Op::Max, f32, {h, next}), next);
        h = select(live, next, h);
        for (size_t j = 0; j < n; ++j) {
            y[j] = select(keep, y4[j], y[j]);
            k1[j] = select(keep, k4[j], k1[j]);
        }
        since = select(keep, b.add(since, tried), since);
    }
    ValueId first = k.add(Inst::make(Op::First, boolean));
    k.yields.push_back({YieldKind::StateNext, stepSlot, 0, select(first, zero, h)});
    k.yields.push_back({YieldKind::Unstable, 0, 0, *missed});
    return y;
}

}  // namespace psys::opt
