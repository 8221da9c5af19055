// Hot reload (rt::System::carryOver): a new system takes over a running one's objects.
// Each documented outcome (docs/runtime.md, "Hot reload") is a case here.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <filesystem>

#include <fmt/format.h>

#include "driver/compile.h"
#include "ir/carried.h"
#include "interp/interpreter.h"
#include "rt/system.h"
#include "tests/run_length.h"
#include "test_support.h"
#include "tests/system_support.h"

using namespace psys;

namespace {

ir::Module compile(const std::string& text) { return test::compileModule(text); }

// Everything drawn, and every type's counts, after each of `frames` steps, as bytes.
std::string run(rt::System& system, int frames) {
    std::string out;
    for (int f = 0; f < frames; ++f) {
        REQUIRE_FALSE(system.step(1.0 / 60));
        for (size_t t = 0; t < system.typeCount(); ++t)
            for (const rt::RenderPoint& p : system.points(t)) test::appendPoint(out, p);
        for (const rt::TypeStats& t : system.stats().types)
            out += std::to_string(t.live) + "/" + std::to_string(t.created) + "/" + std::to_string(t.killed) + "/" +
                   std::to_string(t.frozen) + "/" + std::to_string(t.dropped) + ";";
    }
    return out;
}

void fireAll(rt::System& system) {
    for (const ir::Trigger& t : system.module().triggers) {
        size_t width = 0;
        for (auto& p : t.params) width += static_cast<size_t>(p.type.width);
        std::vector<float> args(width, 1.5f);
        REQUIRE_FALSE(system.fire(t.name, args));
    }
}

const rt::RenderPoint* pointOf(const std::vector<rt::RenderPoint>& points, uint32_t id) {
    for (const auto& p : points)
        if (p.id == id) return &p;
    return nullptr;
}

}  // namespace

TEST_CASE("reloading an unchanged source continues every sample bit for bit") {
    for (auto& entry : std::filesystem::directory_iterator(PSYS_SAMPLES_DIR)) {
        if (entry.path().extension() != ".psys") continue;
        INFO(entry.path().filename().string());
        std::string text = test::readFile(entry.path().string());
        interp::Interpreter a, b;
        rt::System straight(compile(text), a), before(compile(text), a);
        fireAll(straight);
        fireAll(before);
        // (a quarter of the long run: 150 frames on either side of the reload, 50 sanitized)
        const int frames = test::kLongRun / 4;
        std::string first = run(straight, frames), second = run(straight, frames);
        CHECK(run(before, frames) == first);
        // The reloaded system runs on another backend (another memory), as after a switch.
        rt::System after(compile(text), b);
        rt::ReloadReport report = after.carryOver(before);
        CHECK(report.dropped == 0);
        CHECK(report.newSlots.empty());
        CHECK(report.lostSlots.empty());
        CHECK(run(after, frames) == second);
        CHECK(after.time() == straight.time());
        CHECK(after.stats().types.size() == straight.stats().types.size());
    }
}

TEST_CASE("each burst on an edge keeps its own state through a reload: two `when`s in one object") {
    // Each `when` burst's previous condition is a state slot of its own name: once both
    // were `prev#0`, a reload gave the first the second's and bursts fired again.
    std::string text = R"(
        object a { emit b at 20 per second; }
        object b {
            when age > 0.3 { emit c count 2; }
            when age > 0.6 { emit c count 5; }
            kill when age > 1;
            object c { point(vec3(age, 0, 0), white, 1); kill when age > 2; }
        }
        spawn a;)";
    interp::Interpreter a, b;
    rt::System straight(compile(text), a), before(compile(text), a);
    run(straight, 40);
    run(before, 40);
    std::string second = run(straight, 40);
    rt::System after(compile(text), b);
    rt::ReloadReport report = after.carryOver(before);
    CHECK(report.newSlots.empty());
    CHECK(report.lostSlots.empty());
    CHECK(run(after, 40) == second);
}

TEST_CASE("a reload that adds an equation starts its state as at each object's creation") {
    std::string old = "object p(k: float) { pos = integrate(vec3(1, 0, 0)); point(pos, white, k); }\n"
                      "object e { emit p(rand() + 1) at 10 per second; }\nspawn e;";
    std::string added = "object p(k: float) { pos = integrate(vec3(1, 0, 0)); h = snapshot(k * 10 + age);\n"
                        "  point(pos + vec3(0, h, 0), white, k); }\n"
                        "object e { emit p(rand() + 1) at 10 per second; }\nspawn e;";
    interp::Interpreter backend;
    rt::System before(compile(old), backend);
    run(before, 60);
    auto was = before.points(0);
    REQUIRE(was.size() >= 9);
    rt::System after(compile(added), backend);
    rt::ReloadReport report = after.carryOver(before);
    CHECK(report.newSlots == std::vector<std::string>{"p.snapshot@h"});
    CHECK(report.lostSlots.empty());
    CHECK(report.carried == before.stats().types[0].live + before.stats().types[1].live);
    REQUIRE_FALSE(after.step(0));  // a step of length 0: nothing moves
    auto now = after.points(0);
    REQUIRE(now.size() == was.size());
    for (const rt::RenderPoint& p : now) {
        const rt::RenderPoint* q = pointOf(was, p.id);
        REQUIRE(q);
        CHECK(p.position[0] == q->position[0]);          // the integral carried over
        CHECK(p.position[1] == q->size * 10);            // h: k · 10 + age at creation, age 0
        CHECK(p.size == q->size);                        // k carried over
    }
}

TEST_CASE("a reload reports the program's state only: not the values split-kernels carries, renumbered by an edit") {
    // `prev(pos)` is drawn after the update wrote pos: split-kernels carries it in a slot of
    // its own, named by its value, which the added equation renumbers. Every update writes
    // that slot before drawing reads it: nothing of it is new or lost.
    std::string old = "object p { pos = integrate(vec3(1, 0, 0)); point(prev(pos) + vec3(0, prev(pos).x, 0), white, 1); }\nspawn p;";
    std::string edited = "object p { h = 2 * age + 1; pos = integrate(vec3(1, 0, 0));\n"
                         "  point(prev(pos) + vec3(0, prev(pos).x, 0), white, h); }\nspawn p;";
    interp::Interpreter backend;
    rt::System before(compile(old), backend);
    run(before, 30);
    rt::System after(compile(edited), backend);
    auto carried = [](const rt::System& s) {
        std::vector<std::string> names;
        for (const ir::StateSlot& slot : s.module().objects[0].state)
            if (ir::isCarried(slot)) names.push_back(slot.name);
        return names;
    };
    REQUIRE_FALSE(carried(before).empty());
    REQUIRE(carried(before) != carried(after));  // renumbered
    rt::ReloadReport report = after.carryOver(before);
    CHECK(report.newSlots.empty());
    CHECK(report.lostSlots.empty());
    REQUIRE_FALSE(after.step(1.0 / 60));
    REQUIRE(after.points(0).size() == 1);
    CHECK(after.points(0)[0].position[0] == doctest::Approx(0.5).epsilon(1e-4));  // prev(pos): 30 frames of 1/60
}

TEST_CASE("a reload that removes an equation drops its state — the rest carries on") {
    std::string old = "object p { a = integrate(vec3(1, 0, 0)); b = integrate(vec3(0, 2, 0));\n"
                      "  point(a + b, white, 1); }\nspawn p;";
    std::string removed = "object p { a = integrate(vec3(1, 0, 0)); point(a, white, 1); }\nspawn p;";
    interp::Interpreter backend;
    rt::System before(compile(old), backend);
    run(before, 60);
    rt::System after(compile(removed), backend);
    rt::ReloadReport report = after.carryOver(before);
    CHECK(report.newSlots.empty());
    CHECK(report.lostSlots == std::vector<std::string>{"p.integrate@b"});
    run(after, 60);
    REQUIRE(after.points(0).size() == 1);
    CHECK(after.points(0)[0].position[0] == doctest::Approx(2.0).epsilon(1e-4));  // 120 frames of 1/60
    CHECK(after.points(0)[0].position[1] == 0);
}

TEST_CASE("a reload that changes an equation's type starts it afresh") {
    std::string old = "object p { v = integrate(1.0); point(vec3(v), white, 1); }\nspawn p;";
    std::string changed = "object p { v = integrate(vec3(1, 2, 3)); point(v, white, 1); }\nspawn p;";
    interp::Interpreter backend;
    rt::System before(compile(old), backend);
    run(before, 60);
    rt::System after(compile(changed), backend);
    rt::ReloadReport report = after.carryOver(before);
    CHECK(report.newSlots == std::vector<std::string>{"p.integrate@v"});
    CHECK(report.lostSlots == std::vector<std::string>{"p.integrate@v"});
    run(after, 30);
    auto p = after.points(0);
    REQUIRE(p.size() == 1);
    CHECK(p[0].position[0] == doctest::Approx(0.5).epsilon(1e-4));  // from zero, 30 frames
    CHECK(p[0].position[2] == doctest::Approx(1.5).epsilon(1e-4));
}

TEST_CASE("a reload that removes an object type drops its objects and keeps the others") {
    std::string old = "object a { point(vec3(age), white, 1); }\nobject b { point(vec3(-age), white, 1); }\n"
                      "spawn a; spawn b; spawn b;";
    std::string removed = "object a { point(vec3(age), white, 1); }\nspawn a;";
    interp::Interpreter backend;
    rt::System before(compile(old), backend);
    run(before, 30);
    rt::System after(compile(removed), backend);
    rt::ReloadReport report = after.carryOver(before);
    CHECK(report.dropped == 2);
    CHECK(report.droppedTypes == std::vector<std::string>{"b"});
    CHECK(report.carried == 1);
    run(after, 30);
    auto p = after.points(0);
    REQUIRE(p.size() == 1);  // the start does not run again
    CHECK(p[0].position[0] == doctest::Approx(1.0).epsilon(1e-4));  // its age carried on
}

TEST_CASE("a reload keeps parents and children, frozen parents included") {
    // The comet dies at 20 s; its tail reads it frozen until the last tail particle dies.
    // Rows on the host, and in the memory (the parents' readers and frozen rows there).
    std::string text = test::readFile(std::string(PSYS_SAMPLES_DIR) + "/follow_parent.psys");
    for (auto rows : {rt::SystemOptions::Rows::OnHost, rt::SystemOptions::Rows::InMemory}) {
        rt::SystemOptions options;
        options.rows = rows;
        options.drawInStep = false;  // (a type drawn as the step goes keeps its rows on the host)
        interp::Interpreter backend;
        rt::System straight(compile(text), backend, options), before(compile(text), backend, options);
        CHECK(before.pool(0).rowsInMemory() == (rows == rt::SystemOptions::Rows::InMemory));
        run(straight, 1205);
        run(before, 1205);
        REQUIRE(before.stats().types[0].frozen == 1);
        std::string expected = run(straight, 120);
        rt::System after(compile(text), backend, options);
        after.carryOver(before);
        CHECK(after.stats().types[0].frozen == 1);
        CHECK(run(after, 120) == expected);
        CHECK(after.stats().types[0].frozen == 0);  // freed with its last reader
    }
}

TEST_CASE("a reload that adds a child's equation of its parent's age starts it at the child's creation, rows in the memory too") {
    // The new slot's init runs at each carried child's creation time: its parent's age
    // then — whether the children and parents keep their rows on the host or in the memory
    // (the parent rows gathered there, at per-row clocks).
    std::string old = "object comet { pos = vec3(age, 0, 0); emit tail count 2; kill when age > 3;\n"
                      "  object tail { point(comet.pos + vec3(0, age, 0), white, 1); kill when age > 5; } }\n"
                      "object launcher { emit comet at 4 per second; kill when age > 2; }\nspawn launcher;";
    std::string added = "object comet { pos = vec3(age, 0, 0); emit tail count 2; kill when age > 3;\n"
                        "  object tail { h = snapshot(comet.age);\n"
                        "    point(comet.pos + vec3(0, age, h), white, 1); kill when age > 5; } }\n"
                        "object launcher { emit comet at 4 per second; kill when age > 2; }\nspawn launcher;";
    std::vector<std::vector<rt::RenderPoint>> drawn;
    for (auto rows : {rt::SystemOptions::Rows::OnHost, rt::SystemOptions::Rows::InMemory}) {
        rt::SystemOptions options;
        options.rows = rows;
        options.drawInStep = false;
        interp::Interpreter backend;
        rt::System before(compile(old), backend, options);
        CHECK(before.pool(1).rowsInMemory() == (rows == rt::SystemOptions::Rows::InMemory));
        run(before, 200);  // comets dead (frozen) and alive, tails of both
        rt::System after(compile(added), backend, options);
        after.carryOver(before);
        REQUIRE_FALSE(after.step(0));
        drawn.push_back(after.points(1));
    }
    REQUIRE(drawn[0].size() > 10);
    REQUIRE(drawn[0].size() == drawn[1].size());
    for (size_t i = 0; i < drawn[0].size(); ++i) {
        CHECK(drawn[0][i].id == drawn[1][i].id);
        CHECK(drawn[0][i].position[2] == drawn[1][i].position[2]);  // h: the comet's age at the tail's creation
        CHECK(drawn[0][i].position[2] >= 0);
    }
}

TEST_CASE("a reload that removes a child type frees the frozen parents only it read") {
    std::string text = test::readFile(std::string(PSYS_SAMPLES_DIR) + "/follow_parent.psys");
    std::string childless = "object comet { pos = vec3(cos(age) * 5, 3 + sin(age * 2), sin(age) * 5);\n"
                            "  point(pos, white, 4); kill when age > 20; }\nspawn comet;";
    interp::Interpreter backend;
    rt::System before(compile(text), backend);
    run(before, 1205);
    REQUIRE(before.stats().types[0].frozen == 1);
    rt::System after(compile(childless), backend);
    rt::ReloadReport report = after.carryOver(before);
    CHECK(report.droppedTypes == std::vector<std::string>{"comet.tail"});
    CHECK(after.stats().types[0].frozen == 0);
    CHECK(after.stats().types[0].live == 0);
}

TEST_CASE("a reload under another parent type leaves children without a parent") {
    std::string old = "object a { x = age; emit c count 1;\n"
                      "  object c { point(vec3(a.x, a.alive ? 1 : 0, 0), white, 1); } }\nspawn a;";
    std::string moved = "object b { x = age; emit c count 1;\n"
                        "  object c { point(vec3(b.x, b.alive ? 1 : 0, 0), white, 1); } }\nspawn b;";
    interp::Interpreter backend;
    rt::System before(compile(old), backend);
    run(before, 30);
    REQUIRE(before.points(1).size() == 1);
    CHECK(before.points(1)[0].position[1] == 1);
    rt::System after(compile(moved), backend);
    rt::ReloadReport report = after.carryOver(before);
    CHECK(report.droppedTypes == std::vector<std::string>{"a", "a.c"});
    CHECK(after.stats().types[0].live == 0);  // b: no objects (a's are not b's)
}

TEST_CASE("a reload keeps the externs' values where name and type match") {
    std::string old = "extern w: vec3 = 0; extern s: float = 1;\nobject p { point(w * s, white, 1); }\nspawn p;";
    std::string changed = "extern w: vec3 = 0; extern s: vec2 = 1;\nobject p { point(w * s.x, white, 1); }\nspawn p;";
    interp::Interpreter backend;
    rt::System before(compile(old), backend);
    float w[3] = {1, 2, 3}, s = 5;
    REQUIRE_FALSE(before.setExtern("w", w));
    REQUIRE_FALSE(before.setExtern("s", {&s, 1}));
    run(before, 2);
    rt::System after(compile(changed), backend);
    after.carryOver(before);
    CHECK(after.externValue("w")->f == std::array<float, 4>{1, 2, 3, 0});
    auto v = after.externValue("s")->f;  // its type changed: its default
    CHECK(v[0] == 1);
    CHECK(v[1] == 1);
}

TEST_CASE("a reload that adds an object type starts it empty but for the spawns the edit added") {
    std::string old = "object a { point(vec3(age), white, 1); }\nspawn a;";
    std::string added = "object a { point(vec3(age), white, 1); emit b at 60 per second; }\n"
                        "object b { point(vec3(-age), white, 1); }\nspawn a; spawn b;";
    interp::Interpreter backend;
    rt::System before(compile(old), backend);
    run(before, 30);
    rt::System after(compile(added), backend);
    rt::ReloadReport report = after.carryOver(before);
    CHECK(report.carried == 1);
    CHECK(report.dropped == 0);
    CHECK(report.spawned == std::vector<std::string>{"b"});
    CHECK(after.stats().types[1].live == 0);
    run(after, 60);
    CHECK(after.stats().types[0].live == 1);  // `spawn a` is not repeated
    CHECK(after.stats().types[1].created == 61);  // 60 from the carried emitter, 1 the added `spawn b`
}

TEST_CASE("a renamed object type is a removed type and a new one") {
    std::string old = "object spark { point(vec3(age), white, 1); }\nobject e { emit spark at 30 per second; }\nspawn e;";
    std::string renamed = "object ember { point(vec3(age), white, 1); }\nobject e { emit ember at 30 per second; }\nspawn e;";
    interp::Interpreter backend;
    rt::System before(compile(old), backend);
    run(before, 30);
    size_t sparks = before.stats().types[0].live;
    REQUIRE(sparks > 10);
    rt::System after(compile(renamed), backend);
    rt::ReloadReport report = after.carryOver(before);
    CHECK(report.droppedTypes == std::vector<std::string>{"spark"});
    CHECK(report.dropped == sparks);
    CHECK(after.stats().types[0].live == 0);
    CHECK(after.stats().types[1].live == 1);  // the emitter carries on, and emits embers
    run(after, 30);
    CHECK(after.stats().types[0].created == 15);
}

TEST_CASE("a reload that adds a parameter carries the objects — the new parameter reads 0") {
    std::string old = "object p(a: float) { point(vec3(a, 0, 0), white, 1); }\nspawn p(2);";
    std::string added = "object p(a: float, b: float) { point(vec3(a, b + 7, 0), white, 1); }\nspawn p(2, 3);";
    interp::Interpreter backend;
    rt::System before(compile(old), backend);
    run(before, 5);
    rt::System after(compile(added), backend);
    rt::ReloadReport report = after.carryOver(before);
    CHECK(report.carried == 1);
    run(after, 1);
    auto p = after.points(0);
    REQUIRE(p.size() == 1);
    CHECK(p[0].position[0] == 2);  // a carried over
    CHECK(p[0].position[1] == 7);  // b: the old objects never had one
}

TEST_CASE("a reload right after a burst carries every object of it, as if nothing happened") {
    // A trigger creates 200 objects at once; the reload comes before the next step.
    std::string text = test::readFile(std::string(PSYS_SAMPLES_DIR) + "/swamp.psys");
    interp::Interpreter backend;
    rt::System straight(compile(text), backend), before(compile(text), backend);
    run(straight, 10);
    run(before, 10);
    float at[3] = {1, 0, 1};
    REQUIRE_FALSE(straight.fire("explosion", at));
    REQUIRE_FALSE(before.fire("explosion", at));
    size_t debris = static_cast<size_t>(before.typeIndex("debris"));
    REQUIRE(before.stats().types[debris].live == 200);
    rt::System after(compile(text), backend);
    after.carryOver(before);
    CHECK(after.stats().types[debris].live == 200);
    CHECK(run(after, 60) == run(straight, 60));
}

TEST_CASE("a reload that changes the integrator carries the integrals — the new method takes over") {
    // A ball thrown up under drag: its integrals keep their slots (integrate@vel,
    // integrate@pos) whatever the method, so switching carries them and the ball goes on
    // from where it was, now integrated by rk4. (The default method also kept the
    // previous velocity that the drag read, prev@vel: rk4 reads the stage's.)
    auto ball = [](const std::string& method) {
        return "@integrator(" + method + ") object b { vel = vec3(0, 10, 0) + integrate(vec3(0, -9.8, 0) - 0.5 * vel);\n"
               "  pos = integrate(vel); point(pos, vec4(vel, 1), 1); }\nspawn b;";
    };
    interp::Interpreter backend;
    rt::System before(compile(ball("semi_implicit")), backend), stayed(compile(ball("semi_implicit")), backend);
    run(before, 60);
    run(stayed, 60);
    double p1 = before.points(0).at(0).position[1], v1 = before.points(0).at(0).color[1];
    rt::System after(compile(ball("rk4")), backend);
    rt::ReloadReport report = after.carryOver(before);
    CHECK(report.newSlots.empty());
    CHECK(report.lostSlots == std::vector<std::string>{"b.prev@vel"});
    // From the carried (p1, v1), the exact solution one second on; rk4 follows it to its
    // own error (1e-7 m at this step), the default method to its own (centimetres).
    run(after, 60);
    run(stayed, 60);
    const double terminal = -19.6;
    double exact = p1 + terminal * 1.0 + (v1 - terminal) * (1 - std::exp(-0.5)) / 0.5;
    CHECK(std::fabs(after.points(0).at(0).position[1] - exact) < 1e-4);
    CHECK(std::fabs(stayed.points(0).at(0).position[1] - exact) > 1e-2);
    // exact from creation reads no state: its slots stay only as what render reads (the
    // velocity in the colour, the position), rewritten each update from the age. The
    // closed form takes over unchanged by the switch: the ball is where an exact run
    // from the start has it.
    rt::System exactAfter(compile(ball("exact")), backend);
    rt::ReloadReport toExact = exactAfter.carryOver(after);
    CHECK(toExact.lostSlots.empty());
    run(exactAfter, 1);
    rt::System fresh(compile(ball("exact")), backend);
    run(fresh, 121);
    CHECK(exactAfter.points(0).at(0).position[1] == fresh.points(0).at(0).position[1]);
}

TEST_CASE("a reload that adds a spawn spawns it, one the old start had is not repeated, one removed removes nothing") {
    const std::string types = "object a { point(vec3(age), white, 1); }\nobject b { point(vec3(-age), white, 1); }\n";
    interp::Interpreter backend;
    rt::System before(compile(types + "spawn a;"), backend);
    run(before, 30);
    rt::System added(compile(types + "spawn a; spawn b; spawn b;"), backend);
    rt::ReloadReport report = added.carryOver(before);
    CHECK(report.spawned == std::vector<std::string>{"b", "b"});
    run(added, 1);
    CHECK(added.pool(0).live() == 1);  // a's spawn is not repeated
    CHECK(added.pool(1).live() == 2);
    rt::System removed(compile(types + "spawn a;"), backend);
    report = removed.carryOver(added);
    CHECK(report.spawned.empty());
    run(removed, 1);
    CHECK(removed.pool(1).live() == 2);  // the b objects stay
}

TEST_CASE("a reload that lengthens or shortens a trail keeps its objects: the points it has carry on") {
    auto text = [](int n) {
        return fmt::format("object p {{ pos = integrate(vec3(1, 0, 0)); trail(pos, white, 0.1, {}); }}\nspawn p;", n);
    };
    for (auto [from, to] : {std::pair{4, 9}, std::pair{9, 4}}) {
        INFO(from << " points to " << to);
        interp::Interpreter backend;
        rt::System before(compile(text(from)), backend);
        run(before, 30);
        auto was = before.points(0);
        REQUIRE(was.size() == 1);
        rt::System after(compile(text(to)), backend);
        rt::ReloadReport report = after.carryOver(before);
        CHECK(report.carried == 1);
        REQUIRE_FALSE(after.step(1.0 / 60));
        auto now = after.points(0);
        REQUIRE(now.size() == 1);
        CHECK(now[0].position[0] > was[0].position[0]);  // the integral carried over
        REQUIRE(now[0].trail.size() == static_cast<size_t>(to - 1));
        for (const auto& q : now[0].trail) {  // every point behind the head, on its path
            CHECK(q[0] <= now[0].position[0]);
            CHECK(q[0] >= 0.0f);
            CHECK(q[1] == 0.0f);
        }
    }
}

namespace {

// `text` compiled as a host that reloads compiles it, with or without relaxed maths.
ir::Module reloadable(const std::string& text, bool relaxed) {
    SourceManager sources;
    DiagnosticEngine diags(sources);
    CompileOptions options;
    options.pipeline.pass.relaxed = relaxed;
    options.pipeline.pass.reloadable = true;
    auto module = compileText("test.psys", text, sources, diags, options);
    INFO(diags.render());
    REQUIRE(module.has_value());
    return std::move(*module);
}

// What a reload carries of each type: its state slots and its kept parameters, by name.
std::string carried(const ir::Module& m) {
    std::string out;
    for (const ir::Object& o : m.objects) {
        out += o.name + ":";
        for (const ir::StateSlot& slot : o.state)  // (what split-kernels carries: written by each update before it is read)
            if (!ir::isCarried(slot)) out += " " + slot.name;
        out += " |";
        for (const ir::Param& p : o.params) out += p.kept ? " " + p.name : "";
        out += "\n";
    }
    return out;
}

}  // namespace

TEST_CASE("what a reload carries is the program's own, whatever the maths: every sample, relaxed or exact") {
    // Under relaxed maths, integrals of what is fixed at creation become c·age and
    // `c + integrate(e)` one integral that starts at c; neither is a slot a reload can
    // carry, and it lost the velocity or the parameters (opt::PassOptions::reloadable).
    std::vector<std::pair<std::string, std::string>> programs;
    for (auto& entry : std::filesystem::directory_iterator(PSYS_SAMPLES_DIR))
        if (entry.path().extension() == ".psys")
            programs.push_back({entry.path().filename().string(), test::readFile(entry.path().string())});
    // Slots that relaxed maths' x/3 → x·(1/3) makes equal, and exact maths keeps apart: once
    // merged under fast maths only.
    programs.push_back({"two prevs", "object p(v: float) { a = prev(v / 3 + age); b = prev(v * 0.33333334 + age);\n"
                                         "  point(vec3(a, b, 0), white, 1); }\nobject e { emit p(rand()) count 4; }\nspawn e;"});
    for (const auto& [name, text] : programs) {
        INFO(name);
        ir::Module relaxed = reloadable(text, true), exact = reloadable(text, false);
        CHECK(carried(relaxed) == carried(exact));
        for (const ir::Object& o : exact.objects)
            for (const ir::Param& p : o.params) CHECK_MESSAGE(p.kept, o.name << "." << p.name);
        // Relaxed, reloaded onto exact after 30 frames: every slot found, every object kept.
        interp::Interpreter a, b;
        rt::System before(std::move(relaxed), a);
        fireAll(before);
        run(before, 30);
        rt::System after(std::move(exact), b);
        rt::ReloadReport report = after.carryOver(before);
        CHECK(report.dropped == 0);
        CHECK(report.newSlots.empty());
        CHECK(report.lostSlots.empty());
    }
}
