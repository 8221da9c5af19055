#include <doctest/doctest.h>

#include "test_support.h"

using namespace psys;

namespace {

Type typeOf(const test::Checked& c, const std::string& object, const std::string& name) {
    auto& eq = c.equation(object, name);
    for (size_t i = 0; i < eq.names.size(); ++i)
        if (eq.names[i] == name) return eq.types[i];
    return Type::error();
}

bool hasError(const std::string& text, const std::string& message) {
    auto c = test::check(text);
    INFO(c.output);
    return !c.ok() && c.output.find(message) != std::string::npos;
}

}  // namespace

TEST_CASE("scalars broadcast to vectors in arithmetic") {
    auto c = test::check("object a { p = vec3(1, 2, 3) * 2; q = 1 - p; r = p / age; point(p + q + r, red, 1); }");
    REQUIRE_MESSAGE(c.ok(), c.output);
    CHECK(typeOf(c, "a", "p") == Type::vec(3));
    CHECK(typeOf(c, "a", "q") == Type::vec(3));
    CHECK(typeOf(c, "a", "r") == Type::vec(3));
}

TEST_CASE("equations are order-free and their types flow through cycles") {
    // The thesis's §2.4 particle: acc needs vel, vel needs acc (through integrate).
    auto c = test::check(R"(
        extern wind: vec3;
        object p {
            acc = vec3(0, -9.82, 0) + wind - vel;
            pos = origin + integrate(vel);
            vel = vec3(0, 10, 0) + integrate(acc);
            point(pos, red, 1);
        })");
    REQUIRE_MESSAGE(c.ok(), c.output);
    CHECK(typeOf(c, "p", "acc") == Type::vec(3));
    CHECK(typeOf(c, "p", "vel") == Type::vec(3));
    CHECK(typeOf(c, "p", "pos") == Type::vec(3));
}

TEST_CASE("a recursive equation that nothing widens is a float") {
    auto c = test::check("object a { n = 0 -> prev(n) + 1; point(origin, red, n); }");
    REQUIRE_MESSAGE(c.ok(), c.output);
    CHECK(typeOf(c, "a", "n") == Type::scalar());
}

TEST_CASE("a constructor fixes a self-referencing equation's width: no annotation needed") {
    // (x.w read x before its type was known: "float has no components")
    auto c = test::check("object a { x = integrate(vec4(1, age, age * age, -x.w)); point(x.xyz, red, 1); }");
    REQUIRE_MESSAGE(c.ok(), c.output);
    CHECK(typeOf(c, "a", "x") == Type::vec(4));
    auto d = test::check("object a { v = vec2(1, 0) + 0 * prev(vec3(v, 0).xy); point(vec3(v, 0), red, 1); }");
    REQUIRE_MESSAGE(d.ok(), d.output);
    CHECK(typeOf(d, "a", "v") == Type::vec(2));
    // The components are still checked once the type is known.
    CHECK(hasError("object a { x = integrate(vec4(1, age, -x)); point(x.xyz, red, 1); }", "vec4"));
}

TEST_CASE("an annotation fixes a recursive equation's type") {
    auto c = test::check("object a { v: vec2 = 0 + prev(v); point(vec3(v, 0), red, 1); }");
    REQUIRE_MESSAGE(c.ok(), c.output);
    CHECK(typeOf(c, "a", "v") == Type::vec(2));
}

TEST_CASE("composite equations take tuples apart") {
    auto c = test::check(R"(
        fn advance(p: vec3, v: vec3, h: float) -> (vec3, vec3) = (p + v * h, v);
        object b {
            (pos, vel) = (origin, vec3(0, 1, 0)) -> advance(prev(pos), prev(vel), dt);
            point(pos, red, length(vel));
        })");
    REQUIRE_MESSAGE(c.ok(), c.output);
    CHECK(typeOf(c, "b", "pos") == Type::vec(3));
    CHECK(typeOf(c, "b", "vel") == Type::vec(3));
}

TEST_CASE("swizzle types") {
    auto c = test::check("object a { c = vec4(1, 2, 3, 4); x = c.x; xy = c.xy; rgb = c.rgb; zzzz = c.zzzz; "
                         "point(vec3(x, xy) + rgb + zzzz.xyz, c, 1); }");
    REQUIRE_MESSAGE(c.ok(), c.output);
    CHECK(typeOf(c, "a", "x") == Type::scalar());
    CHECK(typeOf(c, "a", "xy") == Type::vec(2));
    CHECK(typeOf(c, "a", "rgb") == Type::vec(3));
    CHECK(typeOf(c, "a", "zzzz") == Type::vec(4));
}

TEST_CASE("built-in signatures") {
    auto c = test::check(R"(object a {
        l = length(vec3(1, 2, 3));
        d = dot(vec2(1, 0), vec2(0, 1));
        n = normalize(vec3(1, 1, 0));
        m = mix(red, blue, 0.5);
        cl = clamp(vec3(2, 3, 4), 0, 1);
        s = smoothstep(0, 1, vec2(0.5, 0.2));
        r = rotate_y(vec3(1, 0, 0), pi);
        x = cross(n, r);
        v = vec4(vec2(1, 2), 3, 4);
        b = vec3(2);
        q = rand3() + nrand();
        point(x + cl + q + b + v.xyz + vec3(s, d + l), m, 1);
    })");
    REQUIRE_MESSAGE(c.ok(), c.output);
    CHECK(typeOf(c, "a", "l") == Type::scalar());
    CHECK(typeOf(c, "a", "d") == Type::scalar());
    CHECK(typeOf(c, "a", "n") == Type::vec(3));
    CHECK(typeOf(c, "a", "m") == Type::vec(4));
    CHECK(typeOf(c, "a", "cl") == Type::vec(3));
    CHECK(typeOf(c, "a", "s") == Type::vec(2));
    CHECK(typeOf(c, "a", "v") == Type::vec(4));
    CHECK(typeOf(c, "a", "b") == Type::vec(3));
    CHECK(typeOf(c, "a", "q") == Type::vec(3));
}

TEST_CASE("type errors") {
    CHECK(hasError("object a { x = vec2(1, 2) + vec3(1, 2, 3); }", "cannot add vec2 and vec3"));
    CHECK(hasError("object a { x = true + 1; }", "cannot add bool and float"));
    CHECK(hasError("object a { x = !age; }", "`!` needs a bool, found float"));
    CHECK(hasError("object a { x = -true; }", "`-` needs a number or vector, found bool"));
    CHECK(hasError("object a { x = vec3(1, 2, 3) == 1; }", "cannot compare vec3 with float"));
    CHECK(hasError("object a { x = age && true; }", "`&&` needs bool operands"));
    CHECK(hasError("object a { x = age > 1 ? true : 1; }", "the two branches have different types: bool and float"));
    CHECK(hasError("object a { x = age ? 1 : 2; }", "a condition must be bool, found float"));
    CHECK(hasError("object a { x = length(vec2(1, 2), vec2(1, 2)); }", "`length` takes 1 argument, but 2 were given"));
    CHECK(hasError("object a { x = distance(vec2(1, 2), vec3(1, 2, 3)); }", "must have the same type, found vec2 and vec3"));
    CHECK(hasError("object a { x = rotate_y(vec3(1, 0, 0), vec2(1, 1)); }", "the angle of `rotate_y` must be a float"));
    CHECK(hasError("object a { x = normalize(2); }", "`normalize` needs a vector, found float"));
    CHECK(hasError("object a { x = sin(true); }", "argument 1 of `sin` must be a number or vector, found bool"));
    CHECK(hasError("object a { x = min(vec2(1, 2), vec3(1, 2, 3)); }", "arguments of `min` have different sizes"));
    CHECK(hasError("object a { x = integrate(true); }", "argument 1 of `integrate` must be a number"));
    CHECK(hasError("object a { x = ((1, 2), 3); }", "tuples cannot be nested"));
    CHECK(hasError("object a(t: (float, float)) { }", "a parameter of an object cannot be a tuple"));
    CHECK(hasError("const c: vec2 = 1;", "constant `c` is declared vec2 but its value is float"));
    CHECK(hasError("fn f() -> float { let a: vec2 = 1; 2 }", "`a` is declared vec2 but its value is float"));
    CHECK(hasError("object a { point(1, red, 1); }", "the position of a point must be vec3, found float"));
    CHECK(hasError("object a { point(origin, red, origin); }", "the size of a point must be float, found vec3"));
    CHECK(hasError("object a { point(origin, 1, 1); }", "the colour of a point must be vec4, found float"));
    CHECK(hasError("object s { } object a { emit s count vec2(1, 1); }", "an emission count must be float"));
    CHECK(hasError("extern e: (float, float);", "an extern cannot be a tuple"));
    CHECK(hasError("const c = (1, 2);", "a constant cannot be a tuple"));
}

TEST_CASE("one mistake gives one error, not a cascade") {
    auto c = test::check("object a { x = undefined_thing * 2; y = x + vec3(1, 2, 3); z = sin(y); point(y, red, z.x); }");
    CHECK(c.diags->errorCount() == 1);
}

TEST_CASE("where time-dependent and random constructs may appear") {
    CHECK(hasError("fn f(x: float) -> float = prev(x);", "`prev` cannot be used in a function"));
    CHECK(hasError("fn f(x: float) -> float = snapshot(x);", "`snapshot` cannot be used in a function"));
    CHECK(hasError("const c = derive(1);", "`derive` cannot be used in a constant"));
    CHECK(hasError("object a { } trigger t { emit a count integrate(1); }", "`integrate` cannot be used in a trigger"));
    CHECK(hasError("@step(rand()) object a { }", "`rand` cannot be used in an attribute"));
    CHECK(hasError("object a { } spawn a count 1;", "expected"));
    CHECK(hasError("object a { } trigger t { emit a count dt; }", "`dt` cannot be used in a trigger"));
    CHECK(hasError("object a(x: float) { } spawn a(age);", "`age` cannot be used in a spawn"));
    CHECK(hasError("extern e: float; fn f() -> float = e;", "extern `e` cannot be used in a function"));
    // Allowed: rand in functions, spawn and trigger arguments; time in triggers.
    auto c = test::check(R"(
        fn jitter() -> float = nrand() * 0.1;
        object a(x: float) { point(vec3(x + jitter()), red, 1); }
        trigger t { emit a(rand() + time) count 3; }
        spawn a(rand());)");
    CHECK_MESSAGE(c.ok(), c.output);
}

TEST_CASE("extern defaults and ranges") {
    auto c = test::check("extern w: vec3 = 1 range(-2, vec3(2, 3, 4)); extern s: float range(-1, 1); extern b: bool = true;");
    CHECK_MESSAGE(c.ok(), c.output);
    CHECK(hasError("extern w: vec3 = vec3(0, 5, 0) range(-2, vec3(2, 3, 4));", "(5) is outside its range [-2, 3]"));
    CHECK(hasError("extern w: float = 1 / 0;", "is not a finite number"));
    CHECK(hasError("const k = 2; fn f() -> float = 1; extern w: float = f();", "must be a constant"));
}

TEST_CASE("warnings: unused equations, hidden names, objects never created") {
    auto c = test::check(R"(
        const speed = 2;
        object a { speed = 3; unused = 4; point(vec3(speed), red, 1); }
        object orphan { point(origin, red, 1); }
        spawn a;)");
    REQUIRE_MESSAGE(c.ok(), c.output);
    CHECK(c.diags->warningCount() == 3);
    CHECK(c.output.find("warning: equation `speed` hides the file-level constant") != std::string::npos);
    CHECK(c.output.find("warning: equation `unused` is never used") != std::string::npos);
    CHECK(c.output.find("warning: object `orphan` is never created") != std::string::npos);
}

TEST_CASE("a failed composite equation does not cascade into its users") {
    auto c = test::check("object a { (p, v) = undefined_fn(1); point(p, red, length(v)); }");
    CHECK(c.diags->errorCount() == 1);
    CHECK(c.output.find("unknown function `undefined_fn`") != std::string::npos);
}

TEST_CASE("cycles through integrate, prev or the next side of -> are legal — others are algebraic loops") {
    auto legal = test::check(R"(object a {
        p = integrate(v); v = 1 - p;               // through integrate
        q = prev(r) + 1; r = q * 2;                // through prev
        n = 0 -> n + 1;                            // through the next side of ->
        point(vec3(p + r + n), red, 1);
    })");
    CHECK_MESSAGE(legal.ok(), legal.output);
    CHECK(hasError("object a { d = derive(e); e = d + age; }", "algebraic loop: `d` needs its own value"));
    CHECK(hasError("object a { x = y ? 1 : 2; y = x > 1; }", "(x → y → x)"));
    // Each loop is reported once, however many equations it has.
    auto c = test::check("object a { a1 = a2; a2 = a3; a3 = a1; b1 = b1 * 2; }");
    CHECK(c.diags->errorCount() == 2);
}

TEST_CASE("a function's parameter or `let`, or a trigger's parameter, is a value even where an object has its name") {
    // (std/noise.psys's `p.yxz`, imported by a program with an object `p`)
    auto c = test::check(R"(
        fn f(p: vec3) -> vec3 { let q = p.yxz; q.zxy + p }
        fn g(v: vec3) -> float { let p = v * 2; p.x }
        trigger t(p: vec3) { emit p(p.xyz); }
        object p(q: vec3) { point(f(q) * g(q), white, 1); }
        spawn p(origin);)");
    CHECK_MESSAGE(c.ok(), c.output);
    // Where no local has the name, an object's name in a function is still an error.
    CHECK(hasError("fn f(v: vec3) -> float = p.x;\nobject p { point(origin, white, 1); }\nspawn p;",
                   "`p` is an object; only the objects declared inside it can read it"));
}
