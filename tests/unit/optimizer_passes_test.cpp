// The optimizing passes on their own (simplify and its rewrite rules, reassociate,
// dead-state, hoist-uniform): IR text in, one pass, IR text out (read and checked by hand).
// The lowering passes are passes_test.cpp.
#include <doctest/doctest.h>

#include "ir/parser.h"
#include "ir/printer.h"
#include "ir/verifier.h"
#include "opt/passes.h"
#include "opt/pattern.h"
#include "pass_support.h"

using namespace psys;
using namespace psys::ir;

namespace {

using test::after;
Module parse(const std::string& text) { return test::parseIr(text); }

void simplifyExact(Module& m, opt::PassErrors& e) { opt::simplify(m, {}, e); }
void simplifyRelaxed(Module& m, opt::PassErrors& e) {
    opt::PassOptions options;
    options.relaxed = true;
    opt::simplify(m, options, e);
}

}  // namespace

TEST_CASE("simplify: constant folding and exact identities") {
    CHECK(after(R"(object p(v: vec3)
  kernel update
    %0 = const.f32 9.82
    %1 = neg.f32 %0
    %2 = const.f32 0.3
    %3 = mul.f32 %1, %2
    %4 = const.f32 0
    %5 = compose.vec3 %4, %3, %4
    %6 = param.vec3 #0
    %7 = const.vec3 1 1 1
    %8 = mul.vec3 %6, %7
    %9 = add.vec3 %8, %5
    %10 = const.vec3 0 0 0
    %11 = add.vec3 %9, %10
    %12 = const.f32 4
    %13 = splat.vec3 %12
    %14 = div.vec3 %11, %13
    %15 = neg.vec3 %14
    %16 = neg.vec3 %15
    yield position = %16
  end
end
)", simplifyExact) == R"(object p(v: vec3)
  kernel update
    %0 = const.vec3 0 -2.946 0
    %1 = param.vec3 #0
    %2 = add.vec3 %0, %1
    %3 = const.vec3 0 0 0
    %4 = add.vec3 %2, %3
    %5 = const.vec3 0.25 0.25 0.25
    %6 = mul.vec3 %4, %5
    yield position = %6
  end
end
)");
}

TEST_CASE("simplify: a kill that is constant false is dropped, with its constant") {
    CHECK(after(R"(object p(v: vec3)
  kernel update
    %0 = const.bool 0
    %1 = param.vec3 #0
    %2 = const.bool 1
    %3 = and.bool %0, %2
    yield kill = %3
    yield position = %1
  end
end
)", simplifyExact) == R"(object p(v: vec3)
  kernel update
    %0 = param.vec3 #0
    yield position = %0
  end
end
)");
}

TEST_CASE("simplify: relaxed maths drops x+0 and divides by multiplying") {
    CHECK(after(R"(object p(v: vec3)
  kernel update
    %0 = param.vec3 #0
    %1 = const.vec3 0 0 0
    %2 = add.vec3 %0, %1
    %3 = const.vec3 3 3 3
    %4 = div.vec3 %2, %3
    yield position = %4
  end
end
)", simplifyRelaxed) == R"(object p(v: vec3)
  kernel update
    %0 = param.vec3 #0
    %1 = const.vec3 0.33333334 0.33333334 0.33333334
    %2 = mul.vec3 %0, %1
    yield position = %2
  end
end
)");
}

TEST_CASE("simplify: a lane used alone is computed alone — vectors rebuilt unchanged are the vector") {
    CHECK(after(R"(object p(u: vec3, v: vec3)
  kernel update
    %0 = param.vec3 #0
    %1 = param.vec3 #1
    %2 = add.vec3 %0, %1
    %3 = extract.f32 %2 #1
    %4 = const.f32 0
    %5 = lt.bool %3, %4
    %6 = extract.f32 %0 #0
    %7 = extract.f32 %0 #1
    %8 = extract.f32 %0 #2
    %9 = compose.vec3 %6, %7, %8
    yield kill = %5
    yield position = %9
  end
end
)", simplifyExact) == R"(object p(u: vec3, v: vec3)
  kernel update
    %0 = param.vec3 #0
    %1 = param.vec3 #1
    %2 = extract.f32 %0 #1
    %3 = extract.f32 %1 #1
    %4 = add.f32 %2, %3
    %5 = const.f32 0
    %6 = lt.bool %4, %5
    yield kill = %6
    yield position = %0
  end
end
)");
}

TEST_CASE("simplify: a snapshot of what is fixed at creation needs no state") {
    std::string out = after(R"(object p(v: vec3)
  kernel behaviour
    %0 = param.vec3 #0
    %1 = const.vec3 2 2 2
    %2 = mul.vec3 %0, %1
    %3 = snapshot.vec3 %2 #0
    %4 = age.f32
    %5 = splat.vec3 %4
    %6 = snapshot.vec3 %5 #1
    yield position = %3
    yield color = %6
  end
end
)", simplifyExact);
    CHECK(out.find("snapshot.vec3 %0") == std::string::npos);
    CHECK(out.find("yield position = %2") != std::string::npos);
    CHECK(out.find("snapshot.vec3 %4 #1") != std::string::npos);  // age changes: kept
}

TEST_CASE("reassociate: (a+b+c)·(a+b+d) written in other orders shares a+b") {
    std::string out = after(R"(object p(a: f32, b: f32, c: f32, d: f32)
  kernel update
    %0 = param.f32 #0
    %1 = param.f32 #1
    %2 = param.f32 #2
    %3 = param.f32 #3
    %4 = add.f32 %2, %0
    %5 = add.f32 %4, %1
    %6 = add.f32 %1, %0
    %7 = add.f32 %6, %3
    %8 = mul.f32 %5, %7
    yield size = %8
  end
end
)", opt::reassociate);
    // After cleaning up: one a+b, used twice.
    Module m = parse(out);
    opt::PassErrors errors;
    opt::simplify(m, {}, errors);
    CHECK(print(m) == R"(object p(a: f32, b: f32, c: f32, d: f32)
  kernel update
    %0 = param.f32 #0
    %1 = param.f32 #1
    %2 = param.f32 #2
    %3 = param.f32 #3
    %4 = add.f32 %0, %1
    %5 = add.f32 %2, %4
    %6 = add.f32 %3, %4
    %7 = mul.f32 %5, %6
    yield size = %7
  end
end
)");
}

TEST_CASE("dead-state: unneeded slots go, equal slots merge, unchanged slots are not stored") {
    Module m = parse(R"(object p(v: vec3, w: f32)
  state a: vec3 next
  state b: vec3 next
  state unused: f32 next
  state fixed: vec3 next
  kernel init
    %0 = param.vec3 #0
    %1 = param.f32 #1
    yield state #0 = %0
    yield state #1 = %0
    yield state #2 = %1
    yield state #3 = %0
  end
  kernel update
    %0 = state.vec3 #0
    %1 = state.vec3 #1
    %2 = add.vec3 %0, %1
    %3 = state.f32 #2
    %4 = const.f32 1
    %5 = add.f32 %3, %4
    %6 = state.vec3 #3
    yield state #0 = %2
    yield state #1 = %2
    yield state #2 = %5
    yield state #3 = %6
  end
  kernel render
    %0 = state.vec3 #1
    %1 = state.vec3 #3
    %2 = add.vec3 %0, %1
    yield position = %2
  end
end
)");
    opt::PassErrors errors;
    opt::deadState(m, {}, errors);
    CHECK(errors.empty());
    CHECK(verify(m).empty());
    // v too is read only by init: the slots hold what is needed afterwards.
    CHECK(print(m) == R"(object p(v: vec3 once, w: f32 once)
  state a: vec3 next
  state fixed: vec3 next
  kernel init
    %0 = param.vec3 #0
    yield state #0 = %0
    yield state #1 = %0
  end
  kernel update
    %0 = state.vec3 #0
    %1 = add.vec3 %0, %0
    yield state #0 = %1
  end
  kernel render
    %0 = state.vec3 #0
    %1 = state.vec3 #1
    %2 = add.vec3 %0, %1
    yield position = %2
  end
end
)");
}

TEST_CASE("simplify: if-floating folds an operation into a choice between constants") {
    CHECK(after(R"(object p()
  kernel update
    %0 = age.f32
    %1 = const.f32 1
    %2 = gt.bool %0, %1
    %3 = const.f32 0.9
    %4 = select.f32 %2, %3, %1
    %5 = const.f32 2
    %6 = mul.f32 %4, %5
    yield size = %6
  end
end
)", simplifyExact) == R"(object p()
  kernel update
    %0 = age.f32
    %1 = const.f32 1
    %2 = gt.bool %0, %1
    %3 = const.f32 2
    %4 = const.f32 1.8
    %5 = select.f32 %2, %4, %3
    yield size = %5
  end
end
)");
}

TEST_CASE("hoist-uniform: what every object of a type computes alike moves to a uniform kernel") {
    std::string out = after(R"(extern g: f32 = 2
object p(v: vec3)
  kernel render
    %0 = param.vec3 #0
    %1 = dt.f32
    %2 = extern.f32 #0
    %3 = mul.f32 %1, %2
    %4 = splat.vec3 %3
    %5 = mul.vec3 %0, %4
    %6 = age.f32
    %7 = mul.f32 %6, %1
    yield position = %5
    yield size = %7
  end
end
)", opt::hoistUniform);
    // dt·g is the same for every object: once per step. The splat stays (it is free), and
    // age·dt depends on the object.
    CHECK(out == R"(extern g: f32 = 2
object p(v: vec3)
  kernel render
    %0 = param.vec3 #0
    %1 = dt.f32
    %2 = uniform.f32 #0
    %3 = splat.vec3 %2
    %4 = mul.vec3 %0, %3
    %5 = age.f32
    %6 = mul.f32 %1, %5
    yield position = %4
    yield size = %6
  end
  kernel uniform.render
    %0 = dt.f32
    %1 = extern.f32 #0
    %2 = mul.f32 %0, %1
    yield uniform #0 = %2
  end
end
)");
}

TEST_CASE("simplify: lane splitting turns mix(green, black, age) into (0, 1 - age, 0, 1)") {
    CHECK(after(R"(object p()
  kernel render
    %0 = const.vec4 0 1 0 1
    %1 = age.f32
    %2 = splat.vec4 %1
    %3 = const.vec4 0 -1 0 0
    %4 = mul.vec4 %2, %3
    %5 = add.vec4 %0, %4
    yield color = %5
  end
end
)", simplifyExact) == R"(object p()
  kernel render
    %0 = age.f32
    %1 = const.f32 0
    %2 = const.f32 1
    %3 = sub.f32 %2, %0
    %4 = compose.vec4 %1, %3, %1, %2
    yield color = %4
  end
end
)");
}

TEST_CASE("rewrite rules: commutative operands match either way, a variable twice is one value, literals by bits") {
    Kernel empty;
    opt::Rewriter rw(empty);
    Kernel& k = rw.to();
    ValueId age = k.op(Op::Age, Type::f32(), {}), dt = k.op(Op::Dt, Type::f32(), {});
    opt::Pat x = opt::var(0);
    opt::Rules rules;
    rules.add(opt::rewrite("x * 1 → x", x * opt::lit(1.0f), x));
    rules.add(opt::rewrite("min(x, x) → x", opt::min(x, x), x));
    rules.add(opt::rewrite("x + -0 → x", x + opt::lit(-0.0f), x));
    const std::string* fired = nullptr;
    auto apply = [&](Op op, ValueId a, ValueId b) { return rules.apply(rw, Inst::make(op, Type::f32(), {a, b}), false, &fired); };
    CHECK(apply(Op::Mul, k.scalar(1), age) == age);  // 1 * x: the commutative match
    CHECK(*fired == "x * 1 → x");
    CHECK(apply(Op::Mul, age, k.scalar(1)) == age);
    CHECK_FALSE(apply(Op::Mul, age, k.scalar(2)));
    CHECK(apply(Op::Min, dt, dt) == dt);
    CHECK_FALSE(apply(Op::Min, dt, age));        // x twice must be one value
    CHECK(apply(Op::Add, age, k.scalar(-0.0f)) == age);
    CHECK_FALSE(apply(Op::Add, age, k.scalar(0.0f)));  // +0 is not −0: −0 + 0 is +0
}

TEST_CASE("rewrite rules build their replacement, folding constants: x / 4 → x * 0.25") {
    Kernel empty;
    opt::Rewriter rw(empty);
    Kernel& k = rw.to();
    ValueId age = k.op(Op::Age, Type::f32(), {});
    opt::Pat x = opt::var(0), c = opt::constant(1);
    opt::Rules rules;
    rules.add(opt::rewrite("x / c → x * (1/c)", x / c, x * (opt::lit(1.0f) / c)));
    auto v = rules.apply(rw, Inst::make(Op::Div, Type::f32(), {age, k.scalar(4)}), false, nullptr);
    REQUIRE(v);
    const Inst& mul = k.at(*v);
    CHECK(mul.op == Op::Mul);
    CHECK(mul.operands[0] == age);
    CHECK(k.at(mul.operands[1]).op == Op::Const);
    CHECK(k.at(mul.operands[1]).constant[0] == 0.25f);
}

namespace {

void recomputeThenDeadState(Module& m, opt::PassErrors& e) {
    opt::recomputeState(m, e);
    opt::deadState(m, {}, e);
}

// The fire's shape: slot #0 holds last step's acc = -v·2 + exp(-age) (v: slot #1), which
// starts as the same function of v's start at age 0. `extra` is spliced into acc.
std::string fireShaped(const std::string& initAcc, const std::string& clock) {
    return R"(object p(iv: f32)
  state prev@v: f32 next
  state v: f32 next
  kernel init
    %0 = param.f32 #0
    %1 = const.f32 -2
    %2 = mul.f32 %0, %1
    %3 = )" + initAcc + R"(
    %4 = neg.f32 %3
    %5 = exp.f32 %4
    %6 = add.f32 %2, %5
    yield state #0 = %6
    yield state #1 = %0
  end
  kernel update
    %0 = state.f32 #1
    %1 = state.f32 #0
    %2 = dt.f32
    %3 = mul.f32 %1, %2
    %4 = add.f32 %0, %3  ; v
    %5 = const.f32 -2
    %6 = mul.f32 %4, %5
    %7 = )" + clock + R"(
    %8 = neg.f32 %7
    %9 = exp.f32 %8
    %10 = add.f32 %6, %9  ; acc
    yield state #0 = %10
    yield state #1 = %4
  end
  kernel render
    %0 = state.f32 #0
    yield size = %0
  end
end
)";
}

}  // namespace

TEST_CASE("recompute-state: last step's acc is computed again from the stored v and age - dt, and not stored") {
    CHECK(after(fireShaped("age.f32", "age.f32"), recomputeThenDeadState) == R"(object p(iv: f32 once)
  state v: f32 next
  kernel init
    %0 = param.f32 #0
    yield state #0 = %0
  end
  kernel update
    %0 = state.f32 #0
    %1 = const.f32 -2
    %2 = mul.f32 %0, %1
    %3 = age.f32
    %4 = dt.f32
    %5 = sub.f32 %3, %4
    %6 = neg.f32 %5
    %7 = exp.f32 %6
    %8 = add.f32 %2, %7  ; acc
    %9 = mul.f32 %4, %8
    %10 = add.f32 %0, %9  ; v
    yield state #0 = %10
  end
  kernel render
    %0 = state.f32 #0
    %1 = const.f32 -2
    %2 = mul.f32 %0, %1
    %3 = age.f32
    %4 = neg.f32 %3
    %5 = exp.f32 %4
    %6 = add.f32 %2, %5  ; acc
    yield size = %6
  end
end
)");
}

TEST_CASE("recompute-state: not when the value reads dt, or starts as another function") {
    // The previous step's dt is not known.
    std::string readsDt = fireShaped("age.f32", "dt.f32");
    CHECK(after(readsDt, opt::recomputeState) == after(readsDt, [](Module&, opt::PassErrors&) {}));
    // Started at exp(-time) but stored as exp(-age): recomputing would change the first step.
    std::string otherStart = fireShaped("time.f32", "age.f32");
    CHECK(after(otherStart, opt::recomputeState) == after(otherStart, [](Module&, opt::PassErrors&) {}));
}

// `when age > 1.04`'s last value: recomputed from `age − dt`, a comparison turns a
// rounding of the clock into a step early, and an edge that never fires (progen seed
// 20164). Nothing is recomputed through an op that jumps (core/ops.h, kJumps).
TEST_CASE("recompute-state: not through a comparison, a rounding to whole numbers or the edge of a domain") {
    const std::string edge = R"(object p()
  state prev#0: bool next
  emit p edge
  kernel init
    %0 = age.f32
    %1 = const.f32 1.04
    %2 = gt.bool %0, %1
    yield state #0 = %2
  end
  kernel update
    %0 = age.f32
    %1 = const.f32 1.04
    %2 = gt.bool %0, %1
    %3 = state.bool #0
    %4 = not.bool %3
    %5 = and.bool %2, %4
    %6 = const.f32 0
    %7 = const.f32 3
    %8 = select.f32 %5, %7, %6
    yield emit.count #0 = %8
    yield state #0 = %2
  end
end
)";
    CHECK(after(edge, opt::recomputeState) == after(edge, [](Module&, opt::PassErrors&) {}));
    // A value through floor: floor(age) one step back may be off by one, not by its last bits.
    std::string floored = fireShaped("age.f32", "age.f32");
    floored.replace(floored.find("%8 = neg.f32 %7"), std::string("%8 = neg.f32 %7").size(), "%8 = floor.f32 %7");
    floored.replace(floored.find("%4 = neg.f32 %3"), std::string("%4 = neg.f32 %3").size(), "%4 = floor.f32 %3");
    CHECK(after(floored, opt::recomputeState) == after(floored, [](Module&, opt::PassErrors&) {}));
    // Nor through the edge of a domain: sqrt(age) recomputed from age − dt where the
    // previous age was 0 may be the root of a rounding below 0, NaN where 0 was stored.
    std::string rooted = fireShaped("age.f32", "age.f32");
    rooted.replace(rooted.find("%8 = neg.f32 %7"), std::string("%8 = neg.f32 %7").size(), "%8 = sqrt.f32 %7");
    rooted.replace(rooted.find("%4 = neg.f32 %3"), std::string("%4 = neg.f32 %3").size(), "%4 = sqrt.f32 %3");
    CHECK(after(rooted, opt::recomputeState) == after(rooted, [](Module&, opt::PassErrors&) {}));
    // (The same shape through neg, continuous, is recomputed: the test above.)
}
