// Remarks, not a pass: where a large argument meets `sin`, `cos` or `tan`.
//
// Why: near 10⁶ one ulp of a float is 0.0625. Fast maths may compute `1e6·k + age` in
// another order, or fused, and round it to a neighbouring float, whose sine is up to that
// much away — the functions themselves are within a few ulp (docs/accuracy.md, "Fast
// maths"). An author who asks (`psysc check --remarks`) is told where. The size of an
// argument is bounded from the constants that build it; an input (age, a parameter, a
// state) counts as about 1, so a remark means a constant that is large, not a proof.
#include <cmath>
#include <set>
#include <tuple>

#include <fmt/format.h>

#include "opt/passes.h"

namespace psys::opt {

using ir::Inst;
using ir::Op;

namespace {

double constantSize(const Inst& i) {
    double most = 0;
    for (int c = 0; c < std::max(1, int(i.type.width)); ++c)
        most = std::max(most, std::fabs(double(i.constant[static_cast<size_t>(c)])));
    return most;
}

}  // namespace

std::vector<PassMessage> largeArgumentRemarks(const ir::Module& module) {
    constexpr double kLarge = 1e4;  // an ulp of 0.001 (2^-10) from 8192 up
    std::vector<PassMessage> out;
    std::set<std::tuple<int32_t, uint32_t, uint32_t>> said;
    for (const ir::Object& object : module.objects)
        for (const ir::Kernel& kernel : object.kernels) {
            const auto& insts = kernel.insts();
            std::vector<double> size(insts.size(), 1);
            for (size_t v = 0; v < insts.size(); ++v) {
                const Inst& i = insts[v];
                auto of = [&](size_t k) { return size[static_cast<size_t>(i.operands.at(k))]; };
                switch (i.op) {
                    case Op::Const: size[v] = constantSize(i); break;
                    case Op::Add: case Op::Sub: case Op::Min: case Op::Max: size[v] = std::max(of(0), of(1)); break;
                    case Op::Mul: size[v] = of(0) * of(1); break;
                    case Op::Div: {
                        const Inst& by = kernel.at(i.operands[1]);
                        double d = by.op == Op::Const ? constantSize(by) : 0;
                        size[v] = d > 0 ? of(0) / d : of(0);
                        break;
                    }
                    case Op::Neg: case Op::Splat: case Op::Extract: case Op::Shuffle: size[v] = of(0); break;
                    case Op::Compose:
                        size[v] = 0;
                        for (size_t k = 0; k < i.operands.size(); ++k) size[v] = std::max(size[v], of(k));
                        break;
                    case Op::Select: size[v] = std::max(of(1), of(2)); break;
                    case Op::Sin: case Op::Cos: case Op::Tan: {
                        double m = of(0);
                        if (m >= kLarge && i.loc.valid() && said.insert({i.loc.file, i.loc.line, i.loc.column}).second) {
                            double ulp = std::ldexp(1.0, std::ilogb(m) - 23);
                            out.push_back({i.loc,
                                           fmt::format("`{}` of a value that may reach {:g}: there a float's ulp is {:g}, "
                                                       "and fast maths may round the argument to a neighbouring float "
                                                       "(exact maths rounds it as written), so the result may differ by "
                                                       "as much (docs/accuracy.md, \"Fast maths\")",
                                                       opInfo(i.op).name, m, ulp),
                                           true, {}, {}});
                        }
                        size[v] = 1;
                        break;
                    }
                    default: size[v] = 1;  // an input, a function's value: about 1
                }
            }
        }
    return out;
}

}  // namespace psys::opt
