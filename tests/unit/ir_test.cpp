// The IR: hash-consing, the text form (print, parse back), the verifier.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "ir/lower.h"
#include "ir/parser.h"
#include "ir/printer.h"
#include "ir/verifier.h"
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
    for (auto& entry : std::filesystem::directory_iterator(PSYS_SAMPLES_DIR)) {
        if (entry.path().extension() != ".psys") continue;
        ++count;
        auto c = test::check(test::readFile(entry.path().string()), entry.path().string());
        REQUIRE_MESSAGE(c.ok(), c.output);
        Module m = lower(*c.program, *c.sources);
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
    // Forward references are allowed through delaying operands of a behaviour kernel.
    CHECK(verifyText("object a()\n  kernel behaviour\n    %0 = prev.f32 %1 #0\n    %1 = age.f32\n  end\nend\n").empty());
}
