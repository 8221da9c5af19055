#include <doctest/doctest.h>

#include <cmath>

#include "core/lanes.h"
#include "frontend/consteval.h"
#include "test_support.h"

using namespace psys;

namespace {

std::optional<ConstValue> valueOf(const std::string& expr, const std::string& prelude = "") {
    auto c = test::check(prelude + "const probe = " + expr + ";");
    REQUIRE_MESSAGE(c.ok(), c.output);
    return evaluateConstant(*static_cast<const ast::ConstDecl&>(c.decl("probe")).value);
}

}  // namespace

TEST_CASE("constant folding of arithmetic, constructors, swizzles and constants") {
    CHECK(valueOf("1 + 2 * 3")->v[0] == 7);
    CHECK(valueOf("-1 / 60")->v[0] == doctest::Approx(-1.0 / 60));
    CHECK(valueOf("-7 % 3")->v[0] == 2);  // floored, as in GLSL's mod
    auto v = valueOf("vec3(1, 2, 3) * 2 + 1");
    CHECK(v->type == Type::vec(3));
    CHECK(v->v[2] == 7);
    CHECK(valueOf("vec4(vec2(1, 2), 3, 4).wzy")->v[0] == 4);
    CHECK(valueOf("k * 2", "const k = 21; ")->v[0] == 42);
    CHECK(valueOf("red.g + pi")->v[0] == doctest::Approx(3.14159265));
    CHECK(valueOf("2 > 1 ? 10 : 20")->v[0] == 10);
    CHECK(valueOf("max(2, vec2(1, 3))")->v[1] == 3);
    CHECK(valueOf("2 > 1 && !(1 == 1)")->isTrue() == false);
}

TEST_CASE("what is not constant is not folded") {
    CHECK_FALSE(valueOf("f(2)", "fn f(x: float) -> float = x; ").has_value());
}

TEST_CASE("constants are computed in float, by the arithmetic the program runs (core/lanes.h)") {
    volatile float tenThousand = 10000, ninety = 90, one = 1, three = 3;
    CHECK(valueOf("sin(10000)")->v[0] == std::sin(static_cast<float>(tenThousand)));
    CHECK(valueOf("1 / 3")->v[0] == static_cast<float>(one) / static_cast<float>(three));
    CHECK(valueOf("radians(90)")->v[0] == static_cast<float>(ninety) * core::kRadiansPerDegree);
    CHECK(valueOf("min(vec2(1, 5), 3)")->v[1] == 3);
}
