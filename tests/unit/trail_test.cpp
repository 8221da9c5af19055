// Trails (docs/language.md, "Drawing"): `trail(pos, colour, width, N)` keeps the position
// of the object's last N updates as state the lowering adds, drawn from the state columns
// — checked against exact answers on the interpreter, and the JIT and GLSL backends with
// it on the samples (samples/wand.psys).
#include <doctest/doctest.h>

#include "ir/printer.h"
#include "run.h"

using namespace psys;
using test::Run;

TEST_CASE("a trail's points are the object's positions at its last updates, nearest first") {
    // x = 2·age: point k + 1 updates back is at x = 2·(age − (k + 1)·dt).
    Run run("object o { trail(vec3(age * 2, 1, 0), white, 0.1, 5); }\nspawn o;");
    const double dt = 1.0 / 64;  // (exact in binary: the ages are exact)
    run.steps(20, dt);
    auto points = run.points("o");
    REQUIRE(points.size() == 1);
    const rt::RenderPoint& p = points[0];
    REQUIRE(p.trail.size() == 4);
    float age = p.position[0] / 2;
    for (size_t k = 0; k < p.trail.size(); ++k) {
        INFO("point " << k + 1 << " back");
        CHECK(p.trail[k][0] == doctest::Approx(2 * (age - (k + 1) * dt)).epsilon(1e-6));
        CHECK(p.trail[k][1] == 1.0f);
        CHECK(p.trail[k][2] == 0.0f);
    }
}

TEST_CASE("a new object's trail starts collapsed at its head and grows one point an update") {
    Run run(R"(
        object t(p: vec3) { pos = snapshot(p) + vec3(age, 0, 0); trail(pos, white, 0.1, 4); }
        object e { emit t(vec3(0, 5, 0)) count 1; }
        spawn e;)");
    run.steps(1, 1.0 / 60);
    auto first = run.points("t");
    REQUIRE(first.size() == 1);
    // Created in the step (at x = 0, y = 5) and advanced to its end: every point behind
    // it is where it was created (not zero: its history starts at its head).
    CHECK(first[0].position[0] > 0.0f);
    for (const auto& q : first[0].trail) {
        CHECK(q[0] == 0.0f);
        CHECK(q[1] == 5.0f);
    }
    run.steps(10, 1.0 / 60);
    auto later = run.points("t");
    REQUIRE(later.size() == 1);
    CHECK(later[0].trail.back()[0] < later[0].trail.front()[0]);  // spread out behind the head
    CHECK(later[0].trail.front()[0] < later[0].position[0]);
}

TEST_CASE("a trail's history is state the IR shows: render yields drawn from state columns, no copy") {
    std::string text = "object o { trail(vec3(age, 0, 0), white, 0.1, 6); }\nspawn o;";
    ir::Module m = test::compileModule(text);
    const ir::Object& o = m.objects.at(0);
    CHECK(o.draw == core::DrawKind::Trail);
    CHECK(o.trail == 6);
    CHECK(ir::renderColumns(o) == ir::kDrawnColumns + 15);
    const ir::Kernel* render = o.kernel(ir::KernelKind::Render);
    REQUIRE(render);
    CHECK(render->find(ir::YieldKind::Trail).size() == 5);
    for (int c = ir::kDrawnColumns; c < ir::renderColumns(o); ++c) {
        INFO(ir::drawnColumnName(c));
        CHECK(render->storage.drawn.at(static_cast<size_t>(c)).from != ir::KernelStorage::Drawn::From::Column);
    }
    std::string printed = ir::print(m);
    CHECK(printed.find("draw trail 6") != std::string::npos);
    CHECK(printed.find("storage drawn trail.5.x = state #") != std::string::npos);
}
