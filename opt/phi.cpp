#include "opt/phi.h"

namespace psys::opt {

using namespace ir;

namespace {

constexpr int kSeriesTerms = 17;
constexpr float kSeriesBelow = 2;

double factorial(int n) { return n <= 1 ? 1.0 : n * factorial(n - 1); }

ValueId scalarPhi(Kernel& k, int n, ValueId z) {
    Type f = Type::f32();
    ValueId negZ = k.op(Op::Neg, f, {z});
    ValueId decay = k.op(Op::Exp, f, {negZ});
    if (n == 0) return decay;
    // Horner: ((c_M·(−z) + c_M−1)·(−z) + …) + c_0 with c_m = 1/(m+n)!.
    ValueId series = k.scalar(static_cast<float>(1 / factorial(kSeriesTerms - 1 + n)));
    for (int m = kSeriesTerms - 2; m >= 0; --m)
        series = k.op(Op::Add, f, {k.op(Op::Mul, f, {series, negZ}), k.scalar(static_cast<float>(1 / factorial(m + n)))});
    ValueId recurrence = decay;
    for (int i = 1; i <= n; ++i)
        recurrence = k.op(Op::Div, f, {k.op(Op::Sub, f, {k.scalar(static_cast<float>(1 / factorial(i - 1))), recurrence}), z});
    ValueId small = k.op(Op::Lt, Type::boolean(), {k.op(Op::Abs, f, {z}), k.scalar(kSeriesBelow)});
    return k.op(Op::Select, f, {small, series, recurrence});
}

}  // namespace

ValueId phi(Kernel& k, int n, ValueId z) {
    Type t = k.at(z).type;
    if (t.width == 1) return scalarPhi(k, n, z);
    if (k.at(z).op == Op::Splat) return k.op(Op::Splat, t, {scalarPhi(k, n, k.at(z).operands[0])});
    std::vector<ValueId> lanes;
    for (int l = 0; l < t.width; ++l) lanes.push_back(scalarPhi(k, n, k.op(Op::Extract, Type::f32(), {z}, l)));
    return k.op(Op::Compose, t, lanes);
}

}  // namespace psys::opt
