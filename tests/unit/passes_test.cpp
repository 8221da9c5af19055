// Each pass on its own: IR text in, one pass, IR text out (read and checked by hand).
#include <doctest/doctest.h>

#include "ir/parser.h"
#include "ir/printer.h"
#include "ir/verifier.h"
#include "opt/passes.h"
#include "opt/pattern.h"

using namespace psys;
using namespace psys::ir;

namespace {

Module parse(const std::string& text) {
    std::string error;
    auto m = parseModule(text, error);
    INFO(error);
    REQUIRE(m.has_value());
    return *m;
}

std::string after(const std::string& text, void (*pass)(Module&, opt::PassErrors&)) {
    Module m = parse(text);
    opt::PassErrors errors;
    pass(m, errors);
    std::string all;
    for (auto& e : errors) all += "error: " + e.text + "\n";
    for (auto& e : verify(m)) all += "malformed: " + e + "\n";
    return all + print(m);
}

void lowerTemporalDefault(Module& m, opt::PassErrors& e) { opt::lowerTemporal(m, {}, e); }
void resolveCycles(Module& m, opt::PassErrors& e) { opt::resolveCycles(m, {}, e); }

}  // namespace

TEST_CASE("resolve-cycles: a recursive reference through integrate becomes prev") {
    // vel = 1 + integrate(acc); acc = 2 - vel
    CHECK(after(R"(object p()
  kernel behaviour
    %0 = const.f32 1
    %1 = recur.f32 %4 #0  ; acc
    %2 = integrate.f32 %1 #1
    %3 = add.f32 %0, %2  ; vel
    %4 = sub.f32 %0, %3  ; acc
    yield size = %3
  end
end
)", resolveCycles) == R"(object p()
  kernel behaviour
    %0 = const.f32 1
    %1 = prev.f32 %4 #0  ; acc
    %2 = integrate.f32 %1 #1
    %3 = add.f32 %0, %2  ; vel
    %4 = sub.f32 %0, %3  ; acc
    yield size = %3
  end
end
)");
}

TEST_CASE("resolve-cycles: a cycle through no delaying construct is an algebraic loop") {
    std::string out = after(R"(object p()
  kernel behaviour
    %0 = recur.f32 %2 #0  ; b
    %1 = add.f32 %0, %0  ; a
    %2 = mul.f32 %1, %1  ; b
    yield size = %2
  end
end
)", resolveCycles);
    CHECK(out.find("error: object p: algebraic loop: b → b → a → b") != std::string::npos);
}

TEST_CASE("scoping: a parent read becomes an export of the parent") {
    CHECK(after(R"(object rocket()
  emit rocket.spark rate
  kernel behaviour
    %0 = age.f32
    %1 = splat.vec3 %0  ; pos
    let pos = %1
  end
end
object rocket.spark()
  parent rocket
  read pos: vec3 ^1
  kernel behaviour
    %0 = parent.read.vec3 #0
    yield position = %0
  end
end
)", opt::scoping) == R"(object rocket()
  emit rocket.spark rate
  export pos: vec3
  kernel behaviour
    %0 = age.f32
    %1 = splat.vec3 %0  ; pos
    let pos = %1
    yield export #0 = %1
  end
end
object rocket.spark()
  parent rocket
  kernel behaviour
    %0 = parent.export.vec3 #0 ^1
    yield position = %0
  end
end
)");
}

TEST_CASE("lower-temporal: integrate, prev, snapshot, derive and -> become state") {
    CHECK(after(R"(object p(v: f32)
  kernel behaviour
    %0 = param.f32 #0
    %1 = integrate.f32 %0 #0  ; x
    %2 = prev.f32 %1 #1
    %3 = snapshot.f32 %1 #2
    %4 = derive.f32 %1 #3
    %5 = fby.f32 %0, %2 #4
    %6 = add.f32 %3, %4
    %7 = add.f32 %5, %6
    yield size = %7
  end
end
)", lowerTemporalDefault) == R"(object p(v: f32)
  state integrate#0: f32 zero
  state prev#1: f32 next
  state snapshot#2: f32 next
  state derive#3: f32 next
  kernel behaviour
    %0 = param.f32 #0
    %1 = first.bool
    %2 = const.f32 0
    %3 = state.f32 #0
    %4 = dt.f32
    %5 = mul.f32 %0, %4
    %6 = add.f32 %3, %5
    %7 = select.f32 %1, %2, %6  ; x
    %8 = state.f32 #1
    %9 = select.f32 %1, %2, %8
    %10 = state.f32 #2
    %11 = select.f32 %1, %7, %10
    %12 = state.f32 #3
    %13 = gt.bool %4, %2
    %14 = sub.f32 %7, %12
    %15 = div.f32 %14, %4
    %16 = not.bool %1
    %17 = and.bool %13, %16
    %18 = select.f32 %17, %15, %2
    %19 = select.f32 %1, %0, %9
    %20 = add.f32 %11, %18
    %21 = add.f32 %19, %20
    yield size = %21
    yield state #0 = %7
    yield state #2 = %11
    yield state #3 = %7
    yield state #1 = %7
  end
end
)");
}

// x = integrate(-x) under the midpoint method.
const char* kMidpointDecay = R"(object p()
  attribute integrator midpoint
  kernel behaviour
    %0 = recur.f32 %2 #0  ; x
    %1 = neg.f32 %0
    %2 = integrate.f32 %1 #1  ; x
    let x = %2
    yield size = %2
  end
end
)";

TEST_CASE("resolve-cycles: under a Runge–Kutta method a cycle through integrate keeps its recur") {
    // The stages read x at their own instant, not the previous update's: unchanged.
    CHECK(after(kMidpointDecay, resolveCycles) == kMidpointDecay);
}

TEST_CASE("lower-temporal: the midpoint method evaluates the derivative at the start and in the middle of the step") {
    // x = integrate(-x): k1 = -x0; x1 = x0 + (0.5 dt)·k1; k2 = -x1; x' = x0 + dt·k2; and the
    // decay rate 1 checked against the limit 2 (k·dt > 2: unstable).
    CHECK(after(kMidpointDecay, lowerTemporalDefault) == R"(object p()
  attribute integrator midpoint
  state integrate@x: f32 zero
  kernel behaviour
    %0 = state.f32 #0
    %1 = neg.f32 %0
    %2 = const.f32 0.5
    %3 = dt.f32
    %4 = mul.f32 %2, %3
    %5 = mul.f32 %1, %4
    %6 = add.f32 %0, %5
    %7 = neg.f32 %6
    %8 = mul.f32 %3, %7
    %9 = add.f32 %0, %8
    %10 = first.bool
    %11 = const.f32 0
    %12 = select.f32 %10, %11, %9
    %13 = const.f32 1
    %14 = mul.f32 %3, %13
    %15 = const.f32 2
    %16 = gt.bool %14, %15
    let x = %12
    yield size = %12
    yield state #0 = %12
    yield unstable = %16
  end
end
)");
}

TEST_CASE("key-random: draws are keyed by object id and draw index") {
    std::string out = after(R"(object p()
  emit p burst
  kernel behaviour
    %0 = rand.f32 #0
    %1 = nrand.vec3 #1 ^1
    yield size = %0
    yield emit.count #0 = %0
  end
end
)", opt::keyRandom);
    INFO(out);
    CHECK(out.find("%0 = object.id.u32\n    %1 = draw.index.u32 #0\n    %2 = rand.f32 %0, %1 #0") != std::string::npos);
    CHECK(out.find("draw.index.u32 #1") == std::string::npos);  // %1 was not used: dropped
}

TEST_CASE("split-kernels: init, update and render; render reads the new state") {
    // pos = integrate(v) with v a parameter; point(pos, white, prev-based size)
    Module m = parse(R"(object p(v: vec3)
  state integrate#0: vec3 zero
  state prev#1: f32 next
  kernel behaviour
    %0 = param.vec3 #0
    %1 = first.bool
    %2 = const.vec3 0 0 0
    %3 = state.vec3 #0
    %4 = dt.f32
    %5 = splat.vec3 %4
    %6 = mul.vec3 %0, %5
    %7 = add.vec3 %3, %6
    %8 = select.vec3 %1, %2, %7  ; pos
    %9 = const.f32 0
    %10 = state.f32 #1
    %11 = select.f32 %1, %9, %10
    %12 = age.f32
    %13 = const.vec4 1 1 1 1
    %14 = const.bool 1
    yield state #0 = %8
    yield state #1 = %12
    yield position = %8
    yield color = %13
    yield size = %11
    yield visible = %14
    yield kill = %1
  end
end
)");
    opt::PassErrors errors;
    opt::splitKernels(m, errors);
    CHECK(errors.empty());
    CHECK(verify(m).empty());
    std::string out = print(m);
    INFO(out);
    // prev's value is needed after the update, so update carries it in a slot of its own.
    CHECK(out.find("state carried%11: f32 next") != std::string::npos);
    // At creation the prev slot starts from age, and prev (hence the carried value) is 0.
    CHECK(out.find(R"(  kernel init
    %0 = const.f32 0
    %1 = age.f32
    yield state #1 = %1
    yield state #2 = %0
  end
)") != std::string::npos);
    // The carried slot takes the prev slot's old value before the slot moves on.
    CHECK(out.find("    %7 = state.f32 #1\n    %8 = age.f32\n    yield state #0 = %6\n    yield state #1 = %8\n"
                   "    yield kill = %1\n    yield state #2 = %7\n") != std::string::npos);
    CHECK(out.find(R"(  kernel render
    %0 = state.vec3 #0
    %1 = const.vec4 1 1 1 1
    %2 = state.f32 #2
    %3 = const.bool 1
    yield position = %0
    yield color = %1
    yield size = %2
    yield visible = %3
  end
)") != std::string::npos);
}

namespace {

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

TEST_CASE("simplify: a lane used alone is computed alone; vectors rebuilt unchanged are the vector") {
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
    opt::deadState(m, errors);
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
