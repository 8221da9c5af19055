// Neighbour folds (docs/language.md, "Neighbours"): what near_count, near_sum, near_min and
// near_max give against what a row of objects one apart makes obvious; who counts as a
// neighbour (within the radius, its edge included; never itself; only the type named);
// when (the last step's values; a new object's first update sees none), over a type
// declared before or after, both ways at once; and that the
// order of a fold's terms is the grid's whatever the threads.
#include <doctest/doctest.h>

#include <algorithm>
#include <limits>

#include "run.h"

using namespace psys;
using test::Run;

namespace {

// Five dots at x = 0 … 4, each drawing its folds as its colour.
const char* kRow = R"(
    object bead(p: vec3) {
        n = near_count(bead, 1);                      // the edge counts: the dots beside it
        s = near_sum(bead, 1, other.p.x);
        lo = near_min(bead, 2.5, other.p.x - p.x);
        hi = near_max(bead, 2.5, other.p.x - p.x);
        point(p, vec4(n, s, lo, hi), 1);
    }
    spawn bead(vec3(0, 0, 0)); spawn bead(vec3(1, 0, 0)); spawn bead(vec3(2, 0, 0));
    spawn bead(vec3(3, 0, 0)); spawn bead(vec3(4, 0, 0));)";

const rt::RenderPoint& at(const std::vector<rt::RenderPoint>& points, float x) {
    auto it = std::find_if(points.begin(), points.end(), [&](const rt::RenderPoint& p) { return p.position[0] == x; });
    REQUIRE(it != points.end());
    return *it;
}

}  // namespace

TEST_CASE("near_count, near_sum, near_min and near_max over a row of dots one apart") {
    Run run(kRow);
    run.steps(1, 1.0 / 60);
    auto points = run.points("bead");
    REQUIRE(points.size() == 5);
    auto expect = [&](float x, float n, float s, float lo, float hi) {
        INFO("the dot at " << x);
        const auto& c = at(points, x).color;
        CHECK(c[0] == n);
        CHECK(c[1] == s);
        CHECK(c[2] == lo);
        CHECK(c[3] == hi);
    };
    expect(0, 1, 1, 1, 2);
    expect(1, 2, 2, -1, 2);
    expect(2, 2, 4, -2, 2);
    expect(3, 2, 6, -2, 1);
    expect(4, 1, 3, -2, -1);
}

TEST_CASE("a fold sees the others as the last step left them, and a new object none in its first update") {
    // A mover goes right one unit a second from x = -0.5; a watcher at the origin, created
    // during the first step, counts it within 0.5. In that step's update it sees no one
    // (empty folds: 0 and the largest float); in the next, the mover where it was.
    Run run(R"(
        object mover { p = vec3(age - 0.5, 0, 0); point(p, white, 1); }
        object watcher {
            n = near_count(mover, 0.5);
            d = near_min(mover, 0.5, abs(other.p.x));
            point(origin, vec4(n, d, age, 1), 1);
        }
        object clock { when age > 0.2 { emit watcher count 1; } }
        spawn mover; spawn clock;)");
    run.steps(1, 0.25);
    auto w = run.points("watcher");
    REQUIRE(w.size() == 1);  // created during this step: no neighbours yet
    CHECK(w[0].color[0] == 0);
    CHECK(w[0].color[1] == std::numeric_limits<float>::max());
    run.steps(1, 0.25);
    w = run.points("watcher");
    REQUIRE(w.size() == 1);
    CHECK(w[0].color[0] == 1);      // the mover at x = -0.25 when the step began
    CHECK(w[0].color[1] == 0.25f);  // (its value then, not this step's 0)
}

TEST_CASE("two types fold over each other, declared in either order, each seeing the other as the last step left it") {
    // Cats at x = 0 and 0.5, mice at 1 and 5. A cat counts the mice within 1 and sums their
    // own count of cats — as the last step left it: 0 after the spawns' first update (a
    // new object sees none), the mouse at 1's two cats from the second step on.
    const std::string cat = R"(
        object cat(p: vec3) {
            mice = near_count(mouse, 1);
            fear = near_sum(mouse, 1, other.cats);
            point(p, vec4(mice, fear, 0, 1), 1);
        })";
    const std::string mouse = R"(
        object mouse(p: vec3) {
            cats = near_count(cat, 1);
            point(p, vec4(cats, 0, 0, 1), 1);
        })";
    const std::string spawns = R"(
        spawn cat(vec3(0, 0, 0)); spawn cat(vec3(0.5, 0, 0)); spawn mouse(vec3(1, 0, 0)); spawn mouse(vec3(5, 0, 0));)";
    for (const std::string& text : {cat + mouse + spawns, mouse + cat + spawns}) {
        INFO(text);
        Run run(text);
        run.steps(1, 1.0 / 60);
        auto cats = run.points("cat"), mice = run.points("mouse");
        REQUIRE(cats.size() == 2);
        REQUIRE(mice.size() == 2);
        CHECK(at(cats, 0).color[0] == 1);
        CHECK(at(cats, 0.5f).color[0] == 1);
        CHECK(at(cats, 0).color[1] == 0);
        CHECK(at(mice, 1).color[0] == 2);
        CHECK(at(mice, 5).color[0] == 0);
        run.steps(1, 1.0 / 60);
        cats = run.points("cat");
        CHECK(at(cats, 0).color[1] == 2);
        CHECK(at(cats, 0.5f).color[1] == 2);
    }
}

TEST_CASE("an object is not its own neighbour, and another type's objects are folded over only where named") {
    Run run(R"(
        object rock(p: vec3) { point(p, white, 1); }
        object dust(p: vec3) {
            rocks = near_count(rock, 1.5);
            motes = near_count(dust, 1.5);
            point(p, vec4(rocks, motes, 0, 1), 1);
        }
        spawn rock(vec3(0, 0, 0)); spawn rock(vec3(0, 0, 1));
        spawn dust(vec3(0, 1, 0)); spawn dust(vec3(5, 0, 0));)");
    run.steps(1, 1.0 / 60);
    auto d = run.points("dust");
    REQUIRE(d.size() == 2);
    const auto& near = at(d, 0);
    CHECK(near.color[0] == 2);  // both rocks (1 and √2 away)
    CHECK(near.color[1] == 0);  // the other mote is 5.1 away, and itself does not count
    CHECK(at(d, 5).color[0] == 0);
}

TEST_CASE("a crowd's folds are the same bits on one thread and on four") {
    std::string repel = test::readFile(std::string(PSYS_SAMPLES_DIR) + "/repel.psys");
    auto run = [&](unsigned threads) {
        rt::SystemOptions options;
        options.threads = threads;
        Run r(repel, options);
        return test::drawnBytes(*r.system, 120);
    };
    CHECK(run(1) == run(4));
}

TEST_CASE("a fold over a crowd spread over many cells finds every neighbour a brute force finds") {
    // 400 dots at random in a cube, the radius a fifth of it: the grid's walk against every pair.
    Run run(R"(
        object bead(p: vec3) {
            n = near_count(bead, 0.2);
            s = near_sum(bead, 0.2, other.p);
            point(p, vec4(n, s), 1);
        }
        object source { emit bead(rand3()) count 400; }
        spawn source;)");
    run.steps(1, 1.0 / 60);
    auto points = run.points("bead");
    REQUIRE(points.size() == 400);
    size_t pairs = 0;
    for (const auto& a : points) {
        float n = 0, sx = 0;
        for (const auto& b : points) {
            if (&a == &b) continue;
            float dx = b.position[0] - a.position[0], dy = b.position[1] - a.position[1],
                  dz = b.position[2] - a.position[2];
            if (dx * dx + dy * dy + dz * dz <= 0.2f * 0.2f) {
                n += 1;
                sx += b.position[0];
            }
        }
        pairs += static_cast<size_t>(n);
        CHECK(a.color[0] == n);
        CHECK(a.color[1] == doctest::Approx(sx).epsilon(1e-5));
    }
    CHECK(pairs > 1000);  // (most dots have neighbours: the walk is tested)
}

TEST_CASE("under @step a fold is the step's: taken once before the first sub-step, the same in every one") {
    // Two walkers 10 apart, moving 1 unit a second, each summing the other's x and
    // integrating that sum in 4 sub-steps of a 1 s step: each step the integral grows by
    // exactly the fold times 1 (4 × its quarter), the fold being the other's x as the
    // last step left it.
    Run run(R"(
        @step(0.25)
        object walker(x0: float) {
            pos = vec3(x0 + age, 0, 0);
            seen = near_sum(walker, 100, other.pos.x);
            total = integrate(seen);
            point(pos, vec4(seen, total, 0, 1), 1);
        }
        spawn walker(0); spawn walker(10);)");
    float lastTotal = 0;
    for (int step = 1; step <= 4; ++step) {
        run.steps(1, 1.0);
        auto w = run.points("walker");
        REQUIRE(w.size() == 2);
        const auto& near = *std::min_element(w.begin(), w.end(), [](auto& a, auto& b) { return a.position[0] < b.position[0]; });
        INFO("step " << step);
        CHECK(near.position[0] == static_cast<float>(step));
        CHECK(near.color[0] == static_cast<float>(10 + step - 1));  // the other at the step's start
        CHECK(near.color[1] - lastTotal == near.color[0]);         // the same fold in each sub-step
        lastTotal = near.color[1];
    }
}
