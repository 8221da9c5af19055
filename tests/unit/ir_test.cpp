// The IR: hash-consing, the text form (print, parse back), the verifier.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <cmath>

#include "core/lanes.h"
#include "driver/compile.h"
#include "ir/evaluate.h"
#include "ir/hash.h"
#include "ir/parser.h"
#include "ir/printer.h"
#include "ir/verifier.h"
#include "lower/lower.h"
#include "opt/passes.h"
#include "test_support.h"

using namespace psys::ir;
namespace test = psys::test;
namespace opt = psys::opt;

namespace {

Module parseOrFail(const std::string& text) {
    std::string error;
    auto m = parseModule(text, error);
    INFO(error);
    REQUIRE(m.has_value());
    return *m;
}

std::string verifyText(const std::string& text) {
    std::string all;
    for (auto& e : verify(parseOrFail(text))) all += e + "\n";
    return all;
}

}  // namespace

TEST_CASE("hash-consing merges equal instructions and orders commutative operands") {
    Kernel k;
    ValueId a = k.scalar(2), b = k.scalar(3);
    CHECK(k.scalar(2) == a);
    ValueId ab = k.op(Op::Add, Type::f32(), {a, b});
    CHECK(k.op(Op::Add, Type::f32(), {b, a}) == ab);
    CHECK(k.op(Op::Sub, Type::f32(), {b, a}) != k.op(Op::Sub, Type::f32(), {a, b}));
    CHECK(k.op(Op::Mul, Type::f32(), {ab, b}) == k.op(Op::Mul, Type::f32(), {b, ab}));
    // A temporal instruction is a call site of its own: never merged.
    CHECK(k.op(Op::Rand, Type::f32(), {}, 1) != k.op(Op::Rand, Type::f32(), {}, 1));
    // 0 and -0 are different constants.
    CHECK(k.scalar(0.0f) != k.scalar(-0.0f));
}

TEST_CASE("every sample's IR prints, parses back and prints the same, before and after the passes") {
    int count = 0;
    // (The examples' effects too: instanced programs, their hidden parameters and lookups.)
    std::vector<std::filesystem::directory_entry> files;
    for (auto& entry : std::filesystem::directory_iterator(PSYS_SAMPLES_DIR)) files.push_back(entry);
    for (auto& entry :
         std::filesystem::directory_iterator(std::filesystem::path(PSYS_SAMPLES_DIR).parent_path() / "examples" / "effects"))
        files.push_back(entry);
    for (auto& entry : files) {
        if (entry.path().extension() != ".psys") continue;
        ++count;
        auto c = test::check(test::readFile(entry.path().string()), entry.path().string());
        REQUIRE_MESSAGE(c.ok(), c.output);
        Module m = psys::lower::lowerProgram(*c.program, *c.sources);
        INFO(entry.path().filename().string());
        std::string problems;
        for (auto& e : verify(m)) problems += e + "\n";
        CHECK_MESSAGE(problems.empty(), problems);
        std::string text = print(m);
        CHECK(print(parseOrFail(text)) == text);
        // With locations too: every instruction has one, and they read back.
        std::string located = print(m, {.locations = true});
        CHECK(print(parseOrFail(located), {.locations = true}) == located);
        opt::PassErrors errors;
        opt::PipelineOptions options;
        options.verifyEach = true;
        bool ok = opt::runPipeline(m, options, errors);
        for (auto& e : errors) problems += e.text + "\n";
        REQUIRE_MESSAGE(ok, problems);
        text = print(m);
        Module back = parseOrFail(text);
        CHECK(print(back) == text);
        CHECK(verify(back).empty());
    }
    CHECK(count >= 12);
}

TEST_CASE("the parser reports what is wrong and where") {
    std::string error;
    CHECK_FALSE(parseModule("object a()\n  kernel update\n    %0 = frob.f32\n  end\nend\n", error));
    CHECK(error == "line 3: unknown instruction `frob`");
    CHECK_FALSE(parseModule("object a()\n  kernel update\n    %0 = const.f33 1\n  end\nend\n", error));
    CHECK(error == "line 3: unknown type `f33`");
    CHECK_FALSE(parseModule("object a()\n  kernel update\n    %1 = age.f32\n  end\nend\n", error));
    CHECK(error == "line 3: expected %0 next, found %1");
    CHECK_FALSE(parseModule("object a()\n  kernel update\n    yield kill = %4\n  end\nend\n", error));
    CHECK(error == "line 4: value %4 is not defined");
    CHECK_FALSE(parseModule("object a()\n", error));
    CHECK(error.find("has no `end`") != std::string::npos);
    CHECK_FALSE(parseModule("object a()\n  draw trail\nend\n", error));
    CHECK(error == "line 2: expected `draw point|sprite|streak` or `draw trail POINTS`");
    CHECK_FALSE(parseModule("object a()\n  draw trail 1\nend\n", error));
    CHECK(error == "line 2: a trail has 2 to 64 points, not 1");
    CHECK_FALSE(parseModule("object a()\n  draw sprite 4\nend\n", error));
    CHECK_FALSE(parseModule("object a()\n  kernel render\n    %0 = const.f32 0\n  storage\n  storage drawn trail.99.x = const 0\n  end\nend\n", error));
    CHECK(error == "line 5: unknown render column `trail.99.x`");
    CHECK_FALSE(parseModule("object a()\n  fold mean: f32 #0\nend\n", error));
    CHECK(error == "line 2: expected `fold sum|min|max|count: type #group`");
    CHECK_FALSE(parseModule("object a()\n  near a\nend\n", error));
    CHECK(error == "line 2: expected `near type radius [position #self #other]`");
    CHECK_FALSE(parseModule("object a()\n  near.read p: vec3 both\nend\n", error));
    CHECK(error == "line 2: expected `near.read name: type self|other`");
}

TEST_CASE("the verifier finds broken invariants") {
    CHECK(verifyText("object a()\n  kernel update\n    %0 = age.f32\n    %1 = add.f32 %0, %2\n    %2 = age.f32\n  end\nend\n")
              .find("%1: operand %2 is not defined before its use") != std::string::npos);
    CHECK(verifyText("object a()\n  kernel update\n    %0 = age.f32\n    %1 = add.vec3 %0, %0\n  end\nend\n")
              .find("operands of the result's type") != std::string::npos);
    CHECK(verifyText("object a()\n  kernel update\n    %0 = state.f32 #0\n  end\nend\n")
              .find("no state slot") != std::string::npos);
    CHECK(verifyText("object a()\n  kernel update\n    %0 = age.f32\n    %1 = integrate.f32 %0 #0\n  end\nend\n")
              .find("`integrate` outside a behaviour kernel") != std::string::npos);
    CHECK(verifyText("object a()\n  kernel render\n    %0 = age.f32\n    yield position = %0\n  end\nend\n")
              .find("a vec3") != std::string::npos);
    CHECK(verifyText("object a()\n  emit nothing rate\nend\n").find("emits unknown `nothing`") != std::string::npos);
    // A trail's point past the object's trail.
    CHECK(verifyText("object a()\n  draw trail 2\n  kernel render\n    %0 = const.vec3 0 0 0\n    yield trail #1 = %0\n  end\nend\n")
              .find("no such point of the object's trail") != std::string::npos);
    // Found by fuzz_ir: a draw with one key operand (it takes none or two) read past its operands.
    CHECK(verifyText("object a()\n  kernel init\n    %0 = object.id.u32\n    %1 = nrand.vec2 %0 #0\n  end\nend\n")
              .find("keyed by two u32") != std::string::npos);
    // Neighbour folds: a fold of a group that is not there, a fold read of the wrong type, a
    // pair kernel's export of the other side that the other has not, a term outside a pair kernel.
    CHECK(verifyText("object a()\n  fold sum: f32 #0\nend\n").find("a fold of a group that does not exist") !=
          std::string::npos);
    CHECK(verifyText("object a()\n  draw point\n  near a 1\n  fold sum: f32 #0\n  kernel update\n    %0 = fold.vec3 #0\n  end\nend\n")
              .find("no fold of this index and type") != std::string::npos);
    CHECK(verifyText("object a()\n  near a 1\n  fold sum: f32 #0\n  kernel pair #0\n    %0 = neighbour.export.f32 #0 ^1\n    yield fold #0 = %0\n  end\nend\n")
              .find("no export of this index and type") != std::string::npos);
    CHECK(verifyText("object a()\n  near a 1\n  fold sum: f32 #0\n  kernel update\n    %0 = const.f32 1\n    yield fold #0 = %0\n  end\nend\n")
              .find("no fold of this index, type and group") != std::string::npos);
    CHECK(verifyText("object a()\n  near nowhere 1\nend\n").find("folds over unknown `nowhere`") != std::string::npos);
    CHECK(verifyText("object a()\n  kernel pair #3\n  end\nend\n").find("a pair kernel of group #3") != std::string::npos);
    // Forward references are allowed through delaying operands of a behaviour kernel.
    CHECK(verifyText("object a()\n  kernel behaviour\n    %0 = prev.f32 %1 #0\n    %1 = age.f32\n  end\nend\n").empty());
}

TEST_CASE("the op table: every op is named, found by its name, and has the properties its kind implies") {
    for (int i = 0; i <= static_cast<int>(Op::Recur); ++i) {
        auto op = static_cast<Op>(i);
        const OpInfo& info = opInfo(op);
        INFO(info.name);
        CHECK(opFromName(info.name) == op);
        if (isLeaf(op)) CHECK(info.arity == 0);
        if (isComponentwise(op)) CHECK(isPure(op));
        if (isCommutative(op)) CHECK(info.arity == 2);
        CHECK(hasOwnSite(op) == (isRandom(op) || isTemporal(op)));
        if (info.delayedOperands) CHECK(isTemporal(op));
    }
    CHECK(mayReferForward(Op::FollowedBy, 1));
    CHECK_FALSE(mayReferForward(Op::FollowedBy, 0));
    CHECK_FALSE(isInput(Op::Const));
    CHECK(isLeaf(Op::Const));
}

TEST_CASE("the structural hash: equal structure hashes alike — names and locations do not count") {
    auto build = [](const char* name, uint32_t line, float constant) {
        Kernel k;
        k.setLoc({0, line, 1, 1});
        ValueId a = k.op(Op::Age, Type::f32(), {});
        ValueId c = k.scalar(constant);
        ValueId s = k.op(Op::Mul, Type::f32(), {a, c});
        k.mutableAt(s).name = name;
        k.yields.push_back({YieldKind::Size, 0, 0, s});
        return k;
    };
    CHECK(structuralHash(build("x", 1, 2)) == structuralHash(build("y", 7, 2)));
    CHECK_FALSE(structuralHash(build("x", 1, 0.0f)) == structuralHash(build("x", 1, -0.0f)));
    Kernel a = build("x", 1, 2), b = a;
    b.yields[0].kind = YieldKind::Visible;
    CHECK_FALSE(structuralHash(a) == structuralHash(b));
    b = a;
    b.kind = KernelKind::Render;
    CHECK_FALSE(structuralHash(a) == structuralHash(b));
}

TEST_CASE("instructions carry the location of the source they come from, through every pass") {
    auto c = test::check("object p {\n  v = integrate(vec3(0, -9.8, 0));\n  point(v * 2, white, age);\n}\nspawn p;",
                         "loc.psys");
    REQUIRE(c.ok());
    Module m = psys::lower::lowerProgram(*c.program, *c.sources);
    opt::PassErrors errors;
    REQUIRE(opt::runPipeline(m, {}, errors));
    const Kernel* update = m.objects[0].kernel(KernelKind::Update);
    REQUIRE(update);
    for (const Inst& i : update->insts()) CHECK(i.loc.valid());
    const Kernel* render = m.objects[0].kernel(KernelKind::Render);
    bool found = false;
    for (const Inst& i : render->insts())
        if (i.op == Op::Mul && i.type == Type::vec(3)) {  // v * 2
            CHECK(i.loc.line == 3);
            CHECK(i.loc.column == 9);
            found = true;
        }
    CHECK(found);
    CHECK(m.files == std::vector<std::string>{"loc.psys"});
    CHECK(print(m, {.locations = true}).find("loc(loc.psys:2:7)") != std::string::npos);
}

TEST_CASE("evaluate computes every componentwise op through core/lanes.h, on every lane") {
    for (int i = 0; i <= static_cast<int>(Op::Recur); ++i) {
        auto op = static_cast<Op>(i);
        if (!isComponentwise(op) || op == Op::Select) continue;
        INFO(opInfo(op).name);
        Inst inst = Inst::make(op, Type::vec(3), {0, 1});
        if (opInfo(op).arity == 1) inst.operands = {0};
        Value x{{0.3f, -2.5f, 7.0f, 0}, 0}, y{{1.5f, 0.25f, -3.0f, 0}, 0};
        Value operands[2] = {x, y};
        Type types[2] = {Type::vec(3), Type::vec(3)};
        Value out = evaluate(inst, operands, types);
        for (size_t l = 0; l < 3; ++l) {
            float expected = opInfo(op).arity == 1 ? psys::core::lane(op, x.f[l]) : psys::core::lane(op, x.f[l], y.f[l]);
            CHECK((out.f[l] == expected || (std::isnan(out.f[l]) && std::isnan(expected))));
        }
        CHECK(out.f[3] == 0);
    }
}

TEST_CASE("lowering reads the values the checker computed: named constants, extern values, attributes") {
    auto c = test::check("extern rate: float = 2 * 3 range(0, 100 / 4);\nconst k = 1 / 4 + 2;\nconst up = vec3(0, k, 0);\n"
                         "@capacity(2 * 8) object p {\n  point(up * k, white, rate);\n}\nspawn p;",
                         "consts.psys");
    REQUIRE_MESSAGE(c.ok(), c.output);
    auto& k = const_cast<psys::ast::ConstDecl&>(static_cast<const psys::ast::ConstDecl&>(c.decl("k")));
    auto& up = static_cast<const psys::ast::ConstDecl&>(c.decl("up"));
    auto& rate = const_cast<psys::ast::ExternDecl&>(static_cast<const psys::ast::ExternDecl&>(c.decl("rate")));
    // What the checker kept on the AST.
    REQUIRE(k.evaluated);
    CHECK(k.evaluated->v[0] == 2.25f);
    REQUIRE(up.evaluated);
    CHECK(up.evaluated->v == std::array<float, 4>{0, 2.25f, 0, 0});
    REQUIRE(rate.defaultEvaluated);
    CHECK(rate.defaultEvaluated->v[0] == 6);
    REQUIRE(rate.highEvaluated);
    CHECK(rate.highEvaluated->v[0] == 25);
    const psys::ast::ObjectDecl& p = c.object("p");
    REQUIRE(p.attributes.size() == 1);
    REQUIRE(p.attributes[0].value);
    CHECK(p.attributes[0].value->v[0] == 16);
    // Lowering computes none of it again: a value changed on the AST is the value lowered.
    k.evaluated->v[0] = 7;
    rate.defaultEvaluated->v[0] = 5;
    Module m = psys::lower::lowerProgram(*c.program, *c.sources);
    CHECK(m.externs.at(0).defaultValue[0] == 5);
    REQUIRE(m.externs.at(0).high);
    CHECK((*m.externs.at(0).high)[0] == 25);
    CHECK(m.objects.at(0).attributes.capacity == 16u);
    const Kernel* behaviour = m.objects.at(0).kernel(KernelKind::Behaviour);
    REQUIRE(behaviour);
    bool seven = false, up3 = false;
    for (const Inst& i : behaviour->insts()) {
        CHECK(i.op != Op::Div);  // 1 / 4 and 100 / 4 were the checker's
        seven |= i.op == Op::Const && i.type == Type::f32() && i.constant[0] == 7;
        up3 |= i.op == Op::Const && i.type == Type::vec(3) && i.constant[1] == 2.25f;
    }
    CHECK(seven);
    CHECK(up3);
}

TEST_CASE("every op that is a built-in function is called in the program the backends are compared on") {
    // tests/programs/every_operation.psys: the LLVM and GLSL backends' differential tests
    // and the GLSL validation run it, so an op added to core/ops.h without a meaning on a
    // backend fails there once this makes the program use it.
    psys::SourceManager sources;
    psys::DiagnosticEngine diags(sources);
    psys::CompileOptions options;
    options.pipeline.optimize = false;
    auto module = psys::compileFile(PSYS_PROGRAMS_DIR "/every_operation.psys", sources, diags, options);
    REQUIRE(module);
    std::set<Op> used;
    for (const Object& o : module->objects)
        for (const Kernel& k : o.kernels)
            for (const Inst& i : k.insts()) used.insert(i.op);
    int builtins = 0;
    for (size_t n = 0; n < psys::core::kOpCount; ++n) {
        auto op = static_cast<Op>(n);
        if (opInfo(op).spelling.builtin.empty()) continue;
        ++builtins;
        INFO(opInfo(op).name);
        CHECK(used.count(op) == 1);
    }
    CHECK(builtins >= 22);
}

TEST_CASE("the verifier finds a storage record that no longer fits its kernel") {
    const std::string head = "object a()\n  state s: vec3 zero\n  kernel render\n    %0 = parent.alive.bool ^1\n";
    // A drawn lane of a slot that does not exist, and a parent read the kernel does not make.
    std::string stale = verifyText(head + "    storage\n    storage drawn position.x = state #1.0\n  end\nend\n");
    CHECK(stale.find("position.x drawn from a state lane that does not exist") != std::string::npos);
    CHECK(stale.find("storage: 0 parent reads for 1") != std::string::npos);
    CHECK(verifyText(head + "    storage\n    storage parent parent.alive #-1 ^1 1\n  end\nend\n").empty());
}
