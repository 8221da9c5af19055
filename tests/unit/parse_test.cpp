// The shape of parsed expressions, seen through the typed AST printer.
#include <doctest/doctest.h>

#include "frontend/frontend.h"
#include "test_support.h"

using namespace psys;

namespace {

// The printed value of equation `x` of object `a` whose body is `body`.
std::string shape(const std::string& body, const std::string& extra = "") {
    auto c = test::check("object a {\n" + extra + "    x = " + body + ";\n}\n");
    REQUIRE_MESSAGE(c.ok(), c.output);
    std::string ast = printAst(*c.program, *c.sources);
    auto start = ast.find("equation x");
    REQUIRE(start != std::string::npos);
    auto eq = ast.find("= ", start) + 2;
    return ast.substr(eq, ast.find("  @", eq) - eq);
}

}  // namespace

TEST_CASE("arithmetic precedence and left associativity") {
    CHECK(shape("1 + 2 * 3") == "(+:float 1 (*:float 2 3))");
    CHECK(shape("1 - 2 - 3") == "(-:float (-:float 1 2) 3)");
    CHECK(shape("(1 + 2) * 3") == "(*:float (+:float 1 2) 3)");
    CHECK(shape("-2 * 3") == "(*:float (neg:float 2) 3)");
    CHECK(shape("8 % 3 / 2") == "(/:float (%:float 8 3) 2)");
}

TEST_CASE("comparison, logic and conditionals") {
    CHECK(shape("age > 1 && age < 2 || !true") ==
          "(||:bool (&&:bool (>:bool age:float 1) (<:bool age:float 2)) (!:bool true))");
    CHECK(shape("age > 1 ? 2 : 3") == "(select:float (>:bool age:float 1) 2 3)");
    CHECK(shape("if age > 1 then 2 else 3") == shape("age > 1 ? 2 : 3"));
    CHECK(shape("age > 1 ? 2 : age > 2 ? 3 : 4") == "(select:float (>:bool age:float 1) 2 (select:float (>:bool age:float 2) 3 4))");
}

TEST_CASE("`->` binds loosest and associates to the right") {
    CHECK(shape("0 -> prev(x) + 1") == "(->:float 0 (+:float (prev:float x:float) 1))");
    CHECK(shape("0 -> 1 -> prev(x)") == "(->:float 0 (->:float 1 (prev:float x:float)))");
    CHECK(shape("0 -> age > 1 ? 1 : 2") == "(->:float 0 (select:float (>:bool age:float 1) 1 2))");
}

TEST_CASE("number literals") {
    CHECK(shape("1e-3") == "1e-3");
    CHECK(shape(".5 + 2.") == "(+:float .5 2.)");
    auto c = test::check("object a { x = 2.5e2; point(origin, red, x); }");
    REQUIRE(c.ok());
    auto& value = static_cast<const ast::NumberExpr&>(*c.equation("a", "x").value);
    CHECK(value.value == 250.0);
}

TEST_CASE("swizzles and member chains") {
    CHECK(shape("vec4(1, 2, 3, 4).zyx.x") == "(.x:float (.zyx:vec3 (vec4:vec4 1 2 3 4)))");
    CHECK(shape("red.rgb") == "(.rgb:vec3 red:vec4)");
}

TEST_CASE("tuples and parentheses") {
    auto c = test::check("object a { (p, v) = (origin, vec3(0, 1, 0)); q = (p); point(q, red, 1); }");
    REQUIRE_MESSAGE(c.ok(), c.output);
    CHECK(c.equation("a", "p").value->kind == ast::ExprKind::Tuple);
    CHECK(c.equation("a", "q").value->kind == ast::ExprKind::Name);
    // The parentheses stay in the range, for carets.
    CHECK(c.equation("a", "q").value->range.end - c.equation("a", "q").value->range.begin == 3);
}

TEST_CASE("comments and non-ASCII text do not shift locations") {
    auto c = test::check("/* ünïcödé → */ object a {\n  // ∫ comment\n  x = 1 + true;\n}\n");
    CHECK_FALSE(c.ok());
    CHECK(c.output.find("test.psys:3:9: error: cannot add float and bool") != std::string::npos);
}

TEST_CASE("every declaration form parses") {
    auto c = test::check(R"(
        @integrator(rk4);
        const k: float = 2;
        fn f(x: float) -> float { let y = x * x; let z: float = y + 1; z * k }
        fn pair(a: vec3) -> (vec3, vec3) = (a, -a);
        extern wind: vec3 = 0 range(-10, 10);
        extern gusty: bool;
        @step(1 / 240) @capacity(1000)
        object e(p: point, c: color) {
            (u, v) = pair(p);
            w = 0 -> prev(w) + f(dt);
            emit e(p, c) at 2 per second count 3;
            emit e(u, c) count 2;
            emit e(v, c);
            when gusty { kill; }
            kill when w > 10;
            point(p + wind, c, 1);
        }
        trigger go(at_pos: point) { emit e(at_pos, white) count 5; }
        spawn e(origin, red);
    )");
    REQUIRE_MESSAGE(c.ok(), c.output);
    auto& e = c.object("e");
    CHECK(e.attributes.size() == 2);
    CHECK(e.commands.size() == 6);
    CHECK(e.commands[0]->rate != nullptr);
    CHECK(e.commands[0]->count != nullptr);
    CHECK(e.commands[1]->rate == nullptr);
    CHECK(e.commands[3]->kind == ast::CommandKind::When);
    CHECK(e.commands[3]->body.front()->cond == nullptr);
    auto& f = static_cast<const ast::FnDecl&>(c.decl("f"));
    CHECK(f.lets.size() == 2);
    CHECK(f.resultType == Type::scalar());
}
