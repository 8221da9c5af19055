// Each lowering pass on its own (resolve-cycles, lower-temporal, key-random, split-kernels;
// scoping in scoping_test.cpp): IR text in, one pass, IR text out (read and checked by hand). The
// optimizing passes are optimizer_passes_test.cpp. At the end, the registry of passes
// against the pipeline and the docs.
#include <doctest/doctest.h>

#include <algorithm>
#include <set>
#include <sstream>

#include "driver/compile.h"
#include "ir/parser.h"
#include "ir/printer.h"
#include "ir/verifier.h"
#include "opt/passes.h"
#include "pass_support.h"
#include "rt/columns.h"
#include "test_support.h"

using namespace psys;
using namespace psys::ir;

namespace {

using test::after;
Module parse(const std::string& text) { return test::parseIr(text); }

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

TEST_CASE("split-kernels: init, update and render — render reads the new state") {
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

// x = snapshot(p0)·3 + integrate(age): under relaxed maths one integral that starts at p0·3.
const char* kFoldable = R"(object p(p0: f32)
  kernel behaviour
    %0 = param.f32 #0
    %1 = snapshot.f32 %0 #0
    %2 = const.f32 3
    %3 = mul.f32 %1, %2
    %4 = age.f32
    %5 = integrate.f32 %4 #1
    %6 = add.f32 %3, %5  ; x
    yield size = %6
  end
end
)";

void lowerTemporalRelaxed(Module& m, opt::PassErrors& e) {
    opt::PassOptions options;
    options.relaxed = true;
    opt::lowerTemporal(m, options, e);
}

TEST_CASE("lower-temporal, relaxed: c + integrate(e) with c fixed at creation is one integral starting at c") {
    CHECK(after(kFoldable, lowerTemporalRelaxed) == R"(object p(p0: f32)
  state snapshot#0: f32 next
  state integrate#1.from-creation: f32 next
  kernel behaviour
    %0 = param.f32 #0
    %1 = first.bool
    %2 = const.f32 0
    %3 = state.f32 #0
    %4 = select.f32 %1, %0, %3
    %5 = const.f32 3
    %6 = mul.f32 %4, %5
    %7 = age.f32
    %8 = state.f32 #1
    %9 = dt.f32
    %10 = mul.f32 %7, %9
    %11 = add.f32 %8, %10
    %12 = mul.f32 %0, %5
    %13 = select.f32 %1, %12, %11  ; x
    yield size = %13
    yield state #0 = %4
    yield state #1 = %13
  end
end
)");
}

// The integral kept apart from its start (the lowering without the fold), up to `x`.
const char* kKeptApart = R"(object p(p0: f32)
  state snapshot#0: f32 next
  state integrate#1: f32 zero
  kernel behaviour
    %0 = param.f32 #0
    %1 = first.bool
    %2 = const.f32 0
    %3 = state.f32 #0
    %4 = select.f32 %1, %0, %3
    %5 = const.f32 3
    %6 = mul.f32 %4, %5
    %7 = age.f32
    %8 = state.f32 #1
    %9 = dt.f32
    %10 = mul.f32 %7, %9
    %11 = add.f32 %8, %10
    %12 = select.f32 %1, %2, %11
    %13 = add.f32 %6, %12  ; x
)";

TEST_CASE("lower-temporal: exact maths, or an integral used elsewhere, keeps c + integrate(e) apart") {
    const std::string tail = "    yield state #0 = %4\n    yield state #1 = %12\n  end\nend\n";
    CHECK(after(kFoldable, lowerTemporalDefault) == kKeptApart + std::string("    yield size = %13\n") + tail);
    std::string twice = kFoldable;
    twice.replace(twice.find("    yield size = %6"), 19, "    %7 = add.f32 %6, %5\n    yield size = %7");
    CHECK(after(twice, lowerTemporalRelaxed) ==
          kKeptApart + std::string("    %14 = add.f32 %12, %13\n    yield size = %14\n") + tail);
}

// The registry of passes (opt::passes()) is the one list: what the pipeline runs, in its
// order, under each level, and what docs/optimizer.md shows.
namespace {

std::vector<std::string> passesPrinted(const std::string& file, bool optimize, bool relaxed) {
    std::ostringstream log;
    CompileOptions options;
    options.pipeline.optimize = optimize;
    options.pipeline.pass.relaxed = relaxed;
    options.pipeline.printAfterAll = true;
    options.pipeline.log = &log;
    SourceManager sources;
    DiagnosticEngine diags(sources);
    REQUIRE(compileFile(file, sources, diags, options).has_value());
    std::vector<std::string> names;
    std::istringstream lines(log.str());
    for (std::string line; std::getline(lines, line);)
        if (line.rfind("; IR after ", 0) == 0) names.push_back(line.substr(11));
    return names;
}

// What --print-after-all prints: the AST lowered (the driver's), then each pass that runs.
std::vector<std::string> registered(bool optimize, bool relaxed) {
    std::vector<std::string> names = {"lowering"};
    for (const opt::PassInfo& pass : opt::passes()) {
        bool runs = pass.runs == opt::PassRuns::Always ||
                    (optimize && (pass.runs == opt::PassRuns::Optimizing || relaxed));
        if (runs) names.push_back(pass.name);
    }
    return names;
}

}  // namespace

TEST_CASE("the pipeline runs the registry's passes in its order, at every level, each printable after") {
    const std::string fire = PSYS_SAMPLES_DIR "/fire.psys";
    std::vector<std::string> all = registered(true, true);
    CHECK(all.size() == opt::passes().size() + 1);
    CHECK(std::find(all.begin(), all.end(), "hoist-uniform") != all.end());
    CHECK(passesPrinted(fire, true, true) == all);
    CHECK(passesPrinted(fire, true, false) == registered(true, false));
    CHECK(passesPrinted(fire, false, false) ==
          std::vector<std::string>{"lowering", "resolve-cycles", "scoping", "lower-temporal", "key-random", "split-kernels",
                                   "double-precision", "lower-storage"});
    std::set<std::string> names;
    for (const opt::PassInfo& pass : opt::passes()) {
        CHECK(names.insert(pass.name).second);  // one name, one pass
        CHECK(std::string(pass.summary).size() > 20);
    }
}

TEST_CASE("docs/optimizer.md's table of passes is the registry's (psysc --list-passes)") {
    std::string docs = test::readFile(PSYS_DOCS_DIR "/optimizer.md");
    const std::string open = "<!-- psysc --list-passes -->\n", close = "<!-- end of psysc --list-passes -->";
    size_t begin = docs.find(open), end = docs.find(close);
    REQUIRE(begin != std::string::npos);
    REQUIRE(end != std::string::npos);
    begin += open.size();
    CHECK(docs.substr(begin, end - begin) == opt::passTable());
}

TEST_CASE("lower-storage: what the run-time stores for each kernel is recorded on it, no instruction changed") {
    std::string in = R"(extern rate: f32 = 30
object comet()
  state integrate@pos: vec3 zero
  emit comet.tail rate
  export pos: vec3
  kernel update
    %0 = const.f32 1
    %1 = state.vec3 #0
    %2 = extern.f32 #0
    %3 = age.f32
    yield emit.rate #0 = %2
    yield emit.count #0 = %0
    yield state #0 = %1
  end
  kernel render
    %0 = state.vec3 #0
    %1 = const.f32 1
    %2 = age.f32
    %3 = const.f32 0.5
    %4 = compose.vec4 %1, %2, %3, %1
    %5 = const.bool 1
    yield position = %0
    yield color = %4
    yield size = %2
    yield visible = %5
  end
end
object comet.tail(k: f32)
  parent comet
  kernel render
    %0 = parent.export.vec3 #0 ^1
    %1 = parent.alive.bool ^1
    %2 = const.vec4 1 1 1 1
    %3 = param.f32 #0
    yield position = %0
    yield color = %2
    yield size = %3
    yield visible = %1
  end
end
)";
    // The rate is the extern, the count the constant 1: every row shares them. The
    // comet's position is its state slot as it is (drawn from the slot's columns), its
    // colour's lanes r, b and a constants (g is its age, a column); the tail's colour is
    // constant, and it reads two values of its parent (gathered into columns, in order).
    CHECK(after(in, opt::lowerStorage) == R"(extern rate: f32 = 30
object comet()
  state integrate@pos: vec3 zero
  emit comet.tail rate
  export pos: vec3
  kernel update
    %0 = const.f32 1
    %1 = state.vec3 #0
    %2 = extern.f32 #0
    %3 = age.f32
    yield emit.rate #0 = %2
    yield emit.count #0 = %0
    yield state #0 = %1
    storage
    storage emit.rate #0 = extern #0
    storage emit.count #0 = const 1
  end
  kernel render
    %0 = state.vec3 #0
    %1 = const.f32 1
    %2 = age.f32
    %3 = const.f32 0.5
    %4 = compose.vec4 %1, %2, %3, %1
    %5 = const.bool 1
    yield position = %0
    yield color = %4
    yield size = %2
    yield visible = %5
    storage
    storage drawn position.x = state #0.0
    storage drawn position.y = state #0.1
    storage drawn position.z = state #0.2
    storage drawn color.r = const 1
    storage drawn color.b = const 0.5
    storage drawn color.a = const 1
  end
end
object comet.tail(k: f32)
  parent comet
  kernel render
    %0 = parent.export.vec3 #0 ^1
    %1 = parent.alive.bool ^1
    %2 = const.vec4 1 1 1 1
    %3 = param.f32 #0
    yield position = %0
    yield color = %2
    yield size = %3
    yield visible = %1
    storage
    storage drawn color.r = const 1
    storage drawn color.g = const 1
    storage drawn color.b = const 1
    storage drawn color.a = const 1
    storage parent parent.export #0 ^1 3
    storage parent parent.alive #-1 ^1 1
  end
end
)");
    // The record reads back as it printed.
    ir::Module m = test::parseIr(in);
    opt::PassErrors errors;
    opt::lowerStorage(m, errors);
    std::string printed = ir::print(m);
    CHECK(ir::print(test::parseIr(printed)) == printed);
}

TEST_CASE("a kernel without a storage record is refused by the run-time with an internal error") {
    ir::Module m = test::parseIr("object a()\n  kernel update\n  end\nend\n");
    const ir::Object& a = m.objects.at(0);
    CHECK_THROWS_WITH_AS(rt::columnLayout(a, *a.kernel(ir::KernelKind::Update)),
                         "internal error: the update kernel of `a` has no storage record (the module was not compiled: "
                         "opt's lower-storage)",
                         std::logic_error);
}

TEST_CASE("lower-storage: an init kernel records the slots a new row must hold zero before it runs") {
    const std::string head = "object p(v: vec3)\n  state a: vec3 zero\n  state b: vec3 next\n  kernel init\n";
    // Init sets b from the parameter: only a is zeroed.
    std::string sets = after(head + "    %0 = param.vec3 #0\n    yield state #1 = %0\n  end\nend\n", opt::lowerStorage);
    CHECK(sets.find("    storage\n    storage zeroed #0\n  end") != std::string::npos);
    // Init reads a slot (before setting it): every slot is zeroed first.
    std::string reads = after(head + "    %0 = state.vec3 #0\n    yield state #1 = %0\n  end\nend\n", opt::lowerStorage);
    CHECK(reads.find("    storage\n    storage zeroed #0 #1\n  end") != std::string::npos);
}
