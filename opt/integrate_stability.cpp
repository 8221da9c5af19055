// The stability check: an explicit method applied to y' = −k·y multiplies y by a factor
// R(k·h) each step, and |R| > 1 once k·h passes the method's limit (core/integrators.h):
// the integral then oscillates with growing amplitude, the stiff drag that reaches 10¹⁴.
// Where the compiler sees k (opt/linear_part.h) it warns at compile time when k is a
// constant beyond the limit at the object's step, and flags every update beyond it at run
// time, so the stats (and the viewer) name the object that went unstable.
#include <fmt/format.h>

#include <cmath>

#include "opt/integrate_methods.h"

namespace psys::opt {

using namespace ir;

namespace {

constexpr float kAssumedFrame = 1.0f / 60;

std::string number(double x) { return fmt::format("{:.4g}", x); }

// A step as the source would write it: 1/120 rather than 0.008333.
std::string stepText(double h) {
    double n = std::round(1 / h);
    return n >= 1 && std::fabs(1 / n - h) <= 1e-6 * h ? fmt::format("1/{}", n) : number(h);
}

void warnIfConstant(const std::string& object, core::Integrator method, float step, const DecayRate& r,
                    PassErrors& errors) {
    if (!r.constant) return;
    double k = 0;
    for (double lane : *r.constant) k = std::max(k, lane);
    double limit = core::stabilityLimit(method);
    double h = step > 0 ? step : kAssumedFrame;
    if (k * h <= limit) return;
    std::string at = step > 0 ? fmt::format("at @step({}) k·dt = {}", stepText(step), number(k * h))
                              : fmt::format("at 60 updates a second k·dt = {}", number(k * h));
    errors.warning(r.loc, fmt::format("object {}: `{}` decays at k = {}/s, and {} is stable only while k·dt < {} "
                                      "(updates shorter than {} ms); {}, so it oscillates and grows. Use "
                                      "@integrator(exponential) or @integrator(exact), or @step(1/{}) or shorter",
                                      object, r.equation, number(k), core::integratorName(method), number(limit),
                                      number(limit / k * 1e3), at, std::ceil(k * 1.05 / limit)),
                   object,
                   {"@integrator(exponential)", "@integrator(exact)",
                    fmt::format("@step(1/{})", std::ceil(k * 1.05 / limit))});
}

}  // namespace

std::optional<ValueId> stabilityCheck(Kernel& to, const std::string& object, core::Integrator method, float step,
                                      const std::vector<DecayRate>& rates, PassErrors& errors) {
    double limit = core::stabilityLimit(method);
    if (limit <= 0) return std::nullopt;
    std::optional<ValueId> any;
    for (const DecayRate& r : rates) {
        warnIfConstant(object, method, step, r, errors);
        if (r.constant && std::max({(*r.constant)[0], (*r.constant)[1], (*r.constant)[2], (*r.constant)[3]}) <= 0)
            continue;  // a constant growth or no decay: never beyond the limit
        LocScope at(to, r.loc);
        ValueId k = r.build();
        Type t = to.at(k).type;
        ValueId dt = to.add(Inst::make(Op::Dt, Type::f32()));
        for (int l = 0; l < t.width; ++l) {
            ValueId lane = t.width == 1 ? k : to.op(Op::Extract, Type::f32(), {k}, l);
            ValueId beyond = to.op(Op::Gt, Type::boolean(), {to.op(Op::Mul, Type::f32(), {lane, dt}),
                                                              to.scalar(static_cast<float>(limit))});
            any = any ? to.op(Op::Or, Type::boolean(), {*any, beyond}) : beyond;
        }
    }
    return any;
}

}  // namespace psys::opt
