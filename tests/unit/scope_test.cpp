// Name resolution: what each name refers to.
#include <doctest/doctest.h>

#include "frontend/checker.h"
#include "test_support.h"

using namespace psys;
using ast::Ref;

namespace {

const ast::NameExpr& nameIn(const ast::Equation& eq) {
    REQUIRE(eq.value->kind == ast::ExprKind::Name);
    return static_cast<const ast::NameExpr&>(*eq.value);
}

}  // namespace

TEST_CASE("names resolve to parameters, equations, constants, externs and built-ins") {
    auto c = test::check(R"(
        const k = 2;
        extern wind: vec3;
        object a(p: float) {
            e1 = p; e2 = e1; e3 = k; e4 = wind; e5 = age; e6 = time; e7 = dt; e8 = pi; e9 = red;
            point(vec3(e2 + e3 + e5 + e6 + e7 + e8) + e4, e9, 1);
        })");
    REQUIRE_MESSAGE(c.ok(), c.output);
    CHECK(nameIn(c.equation("a", "e1")).ref.kind == Ref::Kind::Param);
    CHECK(nameIn(c.equation("a", "e2")).ref.kind == Ref::Kind::Equation);
    CHECK(nameIn(c.equation("a", "e2")).ref.equation == &c.equation("a", "e1"));
    CHECK(nameIn(c.equation("a", "e3")).ref.kind == Ref::Kind::Const);
    CHECK(nameIn(c.equation("a", "e4")).ref.kind == Ref::Kind::Extern);
    CHECK(nameIn(c.equation("a", "e5")).ref.kind == Ref::Kind::Age);
    CHECK(nameIn(c.equation("a", "e6")).ref.kind == Ref::Kind::Time);
    CHECK(nameIn(c.equation("a", "e7")).ref.kind == Ref::Kind::Dt);
    CHECK(nameIn(c.equation("a", "e8")).ref.kind == Ref::Kind::BuiltinConst);
    CHECK(nameIn(c.equation("a", "e9")).ref.kind == Ref::Kind::BuiltinConst);
}

TEST_CASE("a local equation hides a constant of the same name") {
    auto c = test::check("const k = 2; object a { k = vec3(1, 2, 3); x = k; point(x, red, 1); }");
    REQUIRE_MESSAGE(c.ok(), c.output);
    CHECK(nameIn(c.equation("a", "x")).ref.kind == Ref::Kind::Equation);
    CHECK(c.equation("a", "x").types[0] == Type::vec(3));
}

TEST_CASE("live parent reads name the enclosing object and how far up it is") {
    auto c = test::check(R"(
        object top {
            pos = vec3(age);
            emit mid at 1 per second;
            object mid {
                here = top.pos;
                emit leaf at 1 per second;
                point(here, red, 1);
                object leaf {
                    a = top.pos + mid.here;
                    gone = !top.alive;
                    older = mid.age;
                    point(a, gone ? red : blue, older);
                }
            }
        }
        spawn top;)");
    REQUIRE_MESSAGE(c.ok(), c.output);
    auto& a = static_cast<const ast::BinaryExpr&>(*c.equation("leaf", "a").value);
    auto& fromTop = static_cast<const ast::MemberExpr&>(*a.lhs);
    auto& fromMid = static_cast<const ast::MemberExpr&>(*a.rhs);
    CHECK(fromTop.parent == &c.object("top"));
    CHECK(fromTop.parentDepth == 2);
    CHECK(fromTop.parentRef.kind == Ref::Kind::Equation);
    CHECK(fromMid.parent == &c.object("mid"));
    CHECK(fromMid.parentDepth == 1);
    auto& gone = static_cast<const ast::UnaryExpr&>(*c.equation("leaf", "gone").value);
    CHECK(static_cast<const ast::MemberExpr&>(*gone.operand).parentRef.kind == Ref::Kind::Alive);
    CHECK(static_cast<const ast::MemberExpr&>(*c.equation("leaf", "older").value).parentRef.kind == Ref::Kind::Age);
}

TEST_CASE("an emit finds a nested object before a file-level one of the same name") {
    auto c = test::check(R"(
        object spark { point(origin, red, 1); }
        object rocket {
            emit spark at 1 per second;
            object spark { point(vec3(1), blue, 1); }
        }
        object launcher { emit spark at 1 per second; }
        spawn rocket; spawn launcher;)");
    REQUIRE_MESSAGE(c.ok(), c.output);
    CHECK(c.object("rocket").commands[0]->targetDecl == c.object("rocket").children[0].get());
    auto& launcher = c.object("launcher");
    CHECK(launcher.commands[0]->targetDecl == &static_cast<const ast::ObjectDecl&>(c.decl("spark")));
}

TEST_CASE("function parameters and lets are in scope in order") {
    auto c = test::check("fn f(x: float) -> float { let y = x + 1; let z = y * 2; z - x }");
    REQUIRE_MESSAGE(c.ok(), c.output);
    auto bad = test::check("fn f(x: float) -> float { let y = z + 1; let z = 2; y }");
    CHECK(bad.output.find("unknown name `z`") != std::string::npos);
}

TEST_CASE("closest names for suggestions") {
    using detail::closestName;
    CHECK(closestName("vell", {"vel", "pos", "acc"}) == "vel");
    CHECK(closestName("sprak", {"spark", "rocket"}) == "spark");  // a swap is one edit
    CHECK(closestName("position", {"pos", "vel"}).empty());       // too far to be a typo
    CHECK(closestName("x", {"y"}) == "y");
    CHECK(closestName("gravity", {}).empty());
}
