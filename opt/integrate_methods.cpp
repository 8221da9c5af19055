// The explicit Runge–Kutta methods, leapfrog and the exponential Euler method on a
// StepBuilder.
//
// A Runge–Kutta method with s stages evaluates the derivatives s times within a step:
// stage i at age (age − dt) + c_i·dt with each integral at y + dt·Σ a_ij·k_j, then
// y' = y + dt·Σ b_i·k_i (a Butcher tableau). All of an object's integrals move together,
// so a position integrated from a velocity sees the velocity of the same stage. The sums
// are built in one fixed order (below), which tests reproduce to the last bit.
#include <fmt/format.h>

#include <set>

#include "opt/integrate_methods.h"
#include "opt/phi.h"

namespace psys::opt {

using namespace ir;

namespace {

struct Tableau {
    std::vector<float> c;               // stage instants, as fractions of the step
    std::vector<std::vector<float>> a;  // a[i][j]: stage j's weight in stage i's state
    std::vector<float> b;               // y' = y + (scale·dt)·Σ b_i·k_i
    float scale = 1;
    // scale = 1/divisor. Under @precision(double) the sum is divided by it, so the
    // double-precision pass divides in pairs: a float 1/6 would cost the weights 3e-8.
    float divisor = 1;
};

const Tableau& tableau(core::Integrator method) {
    static const Tableau euler{{0}, {{}}, {1}, 1};
    static const Tableau midpoint{{0, 0.5f}, {{}, {0.5f}}, {0, 1}, 1};
    static const Tableau heun{{0, 1}, {{}, {1}}, {1, 1}, 0.5f};
    static const Tableau rk4{{0, 0.5f, 0.5f, 1}, {{}, {0.5f}, {0, 0.5f}, {0, 0, 1}}, {1, 2, 2, 1}, 1.0f / 6, 6};
    switch (method) {
        case core::Integrator::Midpoint: return midpoint;
        case core::Integrator::Rk2: return heun;
        case core::Integrator::Rk4: return rk4;
        default: return euler;
    }
}

// x·dt, where x = 1 is dt itself.
ValueId timesDt(StepBuilder& b, float x) {
    return x == 1 ? b.dt() : b.to().op(Op::Mul, Type::f32(), {b.scalar(x), b.dt()});
}

}  // namespace

std::vector<ValueId> rungeKutta(StepBuilder& b, core::Integrator method, bool exactWeights) {
    const Tableau& t = tableau(method);
    size_t n = b.size();
    std::vector<std::vector<ValueId>> k;  // k[stage][integral]
    for (size_t i = 0; i < t.c.size(); ++i) {
        std::vector<ValueId> y;
        for (size_t j = 0; j < n; ++j) {
            LocScope at(b.to(), b.loc(j));
            ValueId sum = 0;
            bool any = false;
            for (size_t s = 0; s < t.a[i].size(); ++s) {
                if (t.a[i][s] == 0) continue;
                ValueId term = b.mul(timesDt(b, t.a[i][s]), k[s][j]);
                sum = any ? b.add(sum, term) : term;
                any = true;
            }
            y.push_back(any ? b.add(b.start(j), sum) : b.start(j));
        }
        StepBuilder::Point local;
        StepBuilder::Point& point = i == 0 ? b.startPoint() : (local = b.pointAt(t.c[i], y));
        std::vector<ValueId> slopes;
        for (size_t j = 0; j < n; ++j) slopes.push_back(b.at(point, b.derivative(j)));
        k.push_back(slopes);
    }
    std::vector<ValueId> out;
    for (size_t j = 0; j < n; ++j) {
        LocScope at(b.to(), b.loc(j));
        ValueId sum = 0;
        bool any = false;
        for (size_t s = 0; s < t.b.size(); ++s) {
            if (t.b[s] == 0) continue;
            ValueId term = t.b[s] == 1 ? k[s][j] : b.mul(b.scalar(t.b[s]), k[s][j]);
            sum = any ? b.add(sum, term) : term;
            any = true;
        }
        if (exactWeights && t.divisor != 1) {
            ValueId step = b.mul(b.dt(), sum);
            Type type = b.to().at(step).type;
            ValueId divisor = b.to().constant(type, {t.divisor, t.divisor, t.divisor, t.divisor});
            out.push_back(b.add(b.start(j), b.to().op(Op::Div, type, {step, divisor})));
        } else {
            out.push_back(b.add(b.start(j), b.mul(timesDt(b, t.scale), sum)));
        }
    }
    return out;
}

namespace {

// Which integrals leapfrog drifts (the header says which), in integral order.
std::vector<bool> driftIntegrals(const StepBuilder& b) {
    size_t n = b.size();
    std::vector<std::set<size_t>> reads;
    for (size_t j = 0; j < n; ++j) reads.push_back(b.reads(j));
    std::vector<bool> drift(n, false);
    for (size_t j = 0; j < n; ++j) {
        if (reads[j].empty() || reads[j].count(j)) continue;
        bool ok = true;
        for (size_t i = 0; i < n; ++i)
            if (drift[i] && (reads[j].count(i) || reads[i].count(j))) ok = false;
        drift[j] = ok;
    }
    return drift;
}

}  // namespace

std::vector<ValueId> leapfrog(StepBuilder& b) {
    size_t n = b.size();
    std::vector<bool> drift = driftIntegrals(b);
    std::vector<ValueId> out(n), first(n), middle(n), end(n);
    StepBuilder::Point& start = b.startPoint();
    for (size_t j = 0; j < n; ++j) {
        if (drift[j]) {
            middle[j] = b.start(j);  // a drift reads no drift: unread there
            continue;
        }
        first[j] = b.at(start, b.derivative(j));
        LocScope at(b.to(), b.loc(j));
        middle[j] = b.add(b.start(j), b.mul(timesDt(b, 0.5f), first[j]));
        end[j] = b.add(b.start(j), b.mul(b.dt(), first[j]));
    }
    StepBuilder::Point mid = b.pointAt(0.5f, middle);
    for (size_t j = 0; j < n; ++j) {
        if (!drift[j]) continue;
        ValueId slope = b.at(mid, b.derivative(j));
        LocScope at(b.to(), b.loc(j));
        out[j] = end[j] = b.add(b.start(j), b.mul(b.dt(), slope));
    }
    StepBuilder::Point last = b.pointAt(1, end);
    for (size_t j = 0; j < n; ++j) {
        if (drift[j]) continue;
        // K½ + h/2·f_K(end), summed as K + h/2·(f_K(start) + f_K(end)): one rounding into
        // K a step, not two (under constant forces, as few as Euler's).
        ValueId slope = b.at(last, b.derivative(j));
        LocScope at(b.to(), b.loc(j));
        out[j] = b.add(b.start(j), b.mul(timesDt(b, 0.5f), b.add(first[j], slope)));
    }
    return out;
}

std::vector<ValueId> exponentialEuler(StepBuilder& b, const std::vector<bool>& hasLinearPart,
                                      const std::function<ValueId(size_t)>& coefficient) {
    std::vector<ValueId> out;
    for (size_t j = 0; j < b.size(); ++j) {
        ValueId slope = b.at(b.startPoint(), b.derivative(j));
        LocScope at(b.to(), b.loc(j));
        ValueId step = b.dt();
        if (hasLinearPart[j]) {
            // k·dt with k = −c, the decay rate: y + dt·φ1(k·dt)·f.
            Kernel& k = b.to();
            ValueId c = coefficient(j);
            ValueId z = b.mul(k.op(Op::Neg, k.at(c).type, {c}), b.dt());
            step = b.mul(b.dt(), phi(k, 1, z));
        }
        out.push_back(b.add(b.start(j), b.mul(step, slope)));
    }
    return out;
}

}  // namespace psys::opt
