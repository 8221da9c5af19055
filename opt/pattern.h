// Declarative rewrite rules over IR instructions, in the style of Halide's
// `rewrite(x * 1, x)`: a rule is a pattern, a replacement and (optionally) a condition on
// what the pattern bound. A pass lists its rules; `Rules::apply` tries them on an
// instruction whose operands are already in the kernel being built.
//
//   Pat x = var(0), y = var(1);      wildcards: any value (the same var twice: the same value)
//   Pat c = constant(2);             any constant
//   lit(1.0f)                        a constant whose every lane is exactly 1.0f (bits: −0 ≠ +0)
//   x + y, x * y, -x, !x, min(x, y), select(c, a, b), splat(x), …   operations
//
// Commutative operations match their operands in either order. A replacement is built
// with the root's type (inner operations take their operands' type; logic gives bool), and
// an operation of constants in a replacement is folded at once (ir/evaluate), so
// `x * (lit(1) / c)` builds x times the constant 1/c.
#pragma once

#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "ir/ir.h"
#include "opt/rewrite.h"

namespace psys::opt {

struct Pat {
    enum class Kind : uint8_t { Var, AnyConst, Literal, Op } kind = Kind::Var;
    int var = 0;          // Var, AnyConst: the binding slot
    float literal = 0;    // Literal: every lane has these bits
    ir::Op op = ir::Op::Const;
    std::vector<Pat> operands;
};

Pat var(int slot);
Pat constant(int slot);
Pat lit(float value);
Pat operator+(Pat a, Pat b);
Pat operator-(Pat a, Pat b);
Pat operator*(Pat a, Pat b);
Pat operator/(Pat a, Pat b);
Pat operator-(Pat a);
Pat operator!(Pat a);
Pat min(Pat a, Pat b);
Pat max(Pat a, Pat b);
Pat both(Pat a, Pat b);    // and
Pat either(Pat a, Pat b);  // or
Pat select(Pat c, Pat a, Pat b);
Pat splat(Pat a);
Pat extract(Pat a);        // any lane
Pat shuffle(Pat a);        // any lanes

// What a match bound: the value of each slot.
struct Bindings {
    std::array<ir::ValueId, 8> value{};
    std::array<bool, 8> bound{};
    ir::ValueId operator[](int slot) const { return value[static_cast<size_t>(slot)]; }
};

using Condition = std::function<bool(const ir::Kernel& k, const Bindings& b)>;

struct Rule {
    std::string name;   // for people reading a trace: "x * 1 → x"
    Pat from, to;
    Condition when;     // none: always
    bool relaxedOnly = false;
};

Rule rewrite(std::string name, Pat from, Pat to, Condition when = {}, bool relaxedOnly = false);

// Procedural patterns, for rewrites a pattern cannot say (MLIR's matchAndRewrite): given
// the instruction (operands in the new kernel), return its replacement or nothing.
struct ProceduralPattern {
    std::string name;
    ir::Op root;  // the op it applies to; Op::Const for every op
    std::function<std::optional<ir::ValueId>(Rewriter& rw, const ir::Inst& inst)> apply;
    bool relaxedOnly = false;
};

class Rules {
public:
    void add(Rule rule) {
        order_.push_back({true, rules_.size()});
        rules_.push_back(std::move(rule));
    }
    void add(ProceduralPattern pattern) {
        order_.push_back({false, patterns_.size()});
        patterns_.push_back(std::move(pattern));
    }

    // The first rule or pattern, in the order they were added, that applies to `inst`,
    // whose operands are values of the rewriter's new kernel: its replacement, built
    // there. `fired` names it.
    std::optional<ir::ValueId> apply(Rewriter& rw, const ir::Inst& inst, bool relaxed, const std::string** fired) const;

private:
    std::optional<ir::ValueId> tryRule(Rewriter& rw, const Rule& r, const ir::Inst& inst) const;

    std::vector<Rule> rules_;
    std::vector<ProceduralPattern> patterns_;
    std::vector<std::pair<bool, size_t>> order_;  // (declarative, index)
};

// Whether every lane of constant `v` has exactly the bits of `x`.
bool constantAll(const ir::Kernel& k, ir::ValueId v, float x);

}  // namespace psys::opt
