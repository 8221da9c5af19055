// Instance speeds and pause through the C API (include/psys/psys.h, "Instances";
// rt/system_speeds.cpp): an instance at speed v for a step of dt is where one at speed 1
// is after v · dt — its motion, ages, emissions and deaths; paused, it stands still and
// carries on when resumed as if it had not stopped, while the others go on; the
// interpreter and the JIT agree bit for bit; every bad call is an error.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "psys/psys.h"

namespace {

std::string speedMessage(psys_error* e) {
    std::string m = e ? psys_error_message(e) : "";
    psys_error_free(e);
    return m;
}

// tests/programs/paced.psys: sparks at a rate thrown by their fountain's age (no random
// draw: two systems that create in another order draw the same), slowed by a drag that
// has no closed form (an integrator's steps), dying at 0.75 s; a bob in sub-steps.
const std::string kPaced = std::string(PSYS_PROGRAMS_DIR) + "/paced.psys";

struct Paced {
    psys_system* s = nullptr;
    explicit Paced(const char* backend, const char* math = "exact") {
        psys_options o;
        psys_options_init(&o);
        o.backend = backend;
        o.math = math;
        o.threads = 1;
        REQUIRE(speedMessage(psys_compile_file(kPaced.c_str(), &o, &s)) == "");
        REQUIRE(speedMessage(psys_instance_kill(s, 0)) == "");  // the host plays them
    }
    ~Paced() { psys_system_free(s); }
    psys_instance play(float x) {
        std::array<float, 16> m{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, x, 0, 0, 1};
        psys_instance h = 0;
        REQUIRE(speedMessage(psys_play(s, m.data(), &h)) == "");
        return h;
    }
    void step(int frames, double dt) {
        for (int i = 0; i < frames; ++i) REQUIRE(speedMessage(psys_step(s, dt)) == "");
    }
};

// One drawn point: position, then size (a spark's age).
using PacedPoint = std::array<float, 4>;

// Per instance slot, the drawn points of `type`, sorted (two systems' rows may differ).
std::map<int, std::vector<PacedPoint>> pacedPoints(psys_system* s, size_t type) {
    psys_draw d;
    REQUIRE(speedMessage(psys_get_draw(s, type, &d)) == "");
    auto value = [&](const psys_column& c, size_t r) { return c.data ? static_cast<const float*>(c.data)[r] : c.constant; };
    std::map<int, std::vector<PacedPoint>> out;
    for (size_t r = 0; r < d.rows; ++r)
        if (value(d.visible, r) != 0)
            out[static_cast<int>(value(d.instance, r))].push_back(
                {value(d.position[0], r), value(d.position[1], r), value(d.position[2], r), value(d.size, r)});
    for (auto& [slot, points] : out) std::sort(points.begin(), points.end());
    return out;
}

int slotOf(psys_instance h) { return static_cast<int>(h & 0xffffffffu); }

// Whether two instances' points are the same to within what rounding the creation times
// differently leaves (ages differ in their last bits).
void checkSamePoints(const std::vector<PacedPoint>& a, const std::vector<PacedPoint>& b) {
    REQUIRE(a.size() == b.size());
    for (size_t i = 0; i < a.size(); ++i)
        for (size_t c = 0; c < 4; ++c) CHECK(a[i][c] == doctest::Approx(b[i][c]).epsilon(1e-4).scale(1));
}

}  // namespace

TEST_CASE("speeds: an instance at half speed is, after 2 s, where one at full speed is after 1 s") {
    for (const char* backend : {"llvm", "interp"}) {
        CAPTURE(backend);
        // (Alone in its system: the bob's sub-steps are counted at the fastest instance's
        // speed, so that each is as long as the full-speed one's.)
        Paced slow(backend), full(backend);
        psys_instance h = slow.play(0), g = full.play(0);
        REQUIRE(speedMessage(psys_instance_set_speed(slow.s, h, 0.5f)) == "");
        CHECK(psys_instance_speed(slow.s, h) == 0.5f);
        CHECK(psys_instance_speed(full.s, g) == 1.0f);
        slow.step(64, 1.0 / 32);  // 2 s of the system's: 1 s of its own
        full.step(64, 1.0 / 64);  // 1 s
        for (size_t type : {0, 1}) {
            auto a = pacedPoints(slow.s, type), b = pacedPoints(full.s, type);
            CAPTURE(type);
            checkSamePoints(a[slotOf(h)], b[slotOf(g)]);
        }
        // Its last objects die at 2.75 s of its own (the fountain's last sparks): 1.5 s at
        // half speed, then twice as fast, 1 s of the system's is 2 of its own.
        slow.step(32, 1.0 / 32);
        REQUIRE(speedMessage(psys_instance_set_speed(slow.s, h, 2.0f)) == "");
        slow.step(16, 1.0 / 32);  // 2.5 s of its own
        CHECK(psys_instance_life(slow.s, h) == PSYS_PLAYING);
        slow.step(16, 1.0 / 32);  // 3.5 s
        CHECK(psys_instance_life(slow.s, h) == PSYS_FINISHED);
    }
}

TEST_CASE("speeds: a paused instance stands still, and resumed carries on as if it had not stopped") {
    for (const char* backend : {"llvm", "interp"}) {
        CAPTURE(backend);
        Paced paused(backend), straight(backend);
        psys_instance h = paused.play(0), other = paused.play(50), g = straight.play(0);
        paused.step(30, 1.0 / 60);
        straight.step(30, 1.0 / 60);
        REQUIRE(speedMessage(psys_instance_pause(paused.s, h, 1)) == "");
        CHECK(psys_instance_paused(paused.s, h) == 1);
        CHECK(psys_instance_paused(paused.s, other) == 0);
        CHECK(psys_instance_speed(paused.s, h) == 1.0f);  // (kept for its resumption)
        paused.step(1, 1.0 / 60);
        auto still = pacedPoints(paused.s, 0);
        std::vector<PacedPoint> otherBefore = still[slotOf(other)];
        paused.step(45, 1.0 / 60);  // past the fountain's and the sparks' lives, had it gone on
        auto after = pacedPoints(paused.s, 0);
        checkSamePoints(after[slotOf(h)], still[slotOf(h)]);
        CHECK(after[slotOf(other)] != otherBefore);  // the other went on
        CHECK(psys_instance_life(paused.s, h) == PSYS_PLAYING);
        REQUIRE(speedMessage(psys_instance_pause(paused.s, h, 0)) == "");
        paused.step(29, 1.0 / 60);
        straight.step(29, 1.0 / 60);  // (59 steps of its own each)
        for (size_t type : {0, 1}) {
            CAPTURE(type);
            checkSamePoints(pacedPoints(paused.s, type)[slotOf(h)], pacedPoints(straight.s, type)[slotOf(g)]);
        }
    }
}

TEST_CASE("speeds: the interpreter and the JIT's exact maths agree bit for bit at any speed") {
    auto run = [](const char* backend) {
        Paced e(backend);
        psys_instance a = e.play(0), b = e.play(3), c = e.play(6);
        REQUIRE(speedMessage(psys_instance_set_speed(e.s, a, 0.3f)) == "");
        REQUIRE(speedMessage(psys_instance_set_speed(e.s, b, 2.5f)) == "");
        e.step(20, 1.0 / 60);
        REQUIRE(speedMessage(psys_instance_pause(e.s, c, 1)) == "");
        e.step(20, 1.0 / 60);
        REQUIRE(speedMessage(psys_instance_set_speed(e.s, a, 0.0f)) == "");
        REQUIRE(speedMessage(psys_instance_pause(e.s, c, 0)) == "");
        e.step(20, 1.0 / 60);
        return std::make_pair(pacedPoints(e.s, 0), pacedPoints(e.s, 1));
    };
    auto interp = run("interp"), jit = run("llvm");
    CHECK(interp.first.size() == 3);
    CHECK(interp == jit);
}

TEST_CASE("speeds: bad speeds and handles are errors that change nothing") {
    Paced e("llvm");
    psys_instance h = e.play(0);
    for (float bad : {-1.0f, NAN, INFINITY, 101.0f}) {
        CAPTURE(bad);
        CHECK(speedMessage(psys_instance_set_speed(e.s, h, bad)).find("from 0 to 100") != std::string::npos);
    }
    CHECK(psys_instance_speed(e.s, h) == 1.0f);
    CHECK(speedMessage(psys_instance_set_speed(e.s, 77, 2)).find("there is no instance 0x4d") != std::string::npos);
    CHECK(speedMessage(psys_instance_pause(e.s, 77, 1)).find("there is no instance") != std::string::npos);
    CHECK(speedMessage(psys_instance_set_speed(nullptr, h, 2)).find("system") != std::string::npos);
    CHECK(psys_instance_speed(e.s, 77) == -1.0f);
    CHECK(psys_instance_paused(e.s, 77) == -1);
    CHECK(psys_instance_paused(nullptr, h) == -1);
    // A slot played again starts at speed 1, not paused.
    REQUIRE(speedMessage(psys_instance_set_speed(e.s, h, 3)) == "");
    REQUIRE(speedMessage(psys_instance_pause(e.s, h, 1)) == "");
    REQUIRE(speedMessage(psys_instance_kill(e.s, h)) == "");
    e.step(1, 1.0 / 60);
    CHECK(psys_instance_speed(e.s, h) == -1.0f);
    psys_instance again = e.play(0);
    CHECK(slotOf(again) == slotOf(h));
    CHECK(psys_instance_speed(e.s, again) == 1.0f);
    CHECK(psys_instance_paused(e.s, again) == 0);
    // A program that is not instanced has none to pace.
    psys_options o;
    psys_options_init(&o);
    psys_system* plain = nullptr;
    REQUIRE(speedMessage(psys_compile_string("object p { point(vec3(age), white, 1); } spawn p;", "p.psys", &o, &plain)) ==
            "");
    CHECK(speedMessage(psys_instance_set_speed(plain, 0, 2)).find("not instanced") != std::string::npos);
    psys_system_free(plain);
}

TEST_CASE("speeds: the system's own instance, finished while paused, plays a trigger's objects again at speed 1") {
    psys_options o;
    psys_options_init(&o);
    o.threads = 1;
    psys_system* s = nullptr;
    REQUIRE(speedMessage(psys_compile_string(R"(
        object mote { point(instance.pos + vec3(age, 0, 0), white, 1); kill when age > 0.5; }
        trigger go { emit mote count 1; }
        spawn mote;)", "mote.psys", &o, &s)) == "");
    REQUIRE(speedMessage(psys_step(s, 0.1)) == "");
    REQUIRE(speedMessage(psys_instance_set_speed(s, 0, 3)) == "");
    REQUIRE(speedMessage(psys_instance_pause(s, 0, 1)) == "");
    REQUIRE(speedMessage(psys_instance_kill(s, 0)) == "");
    REQUIRE(speedMessage(psys_step(s, 0.1)) == "");
    CHECK(psys_instance_life(s, 0) == PSYS_FINISHED);
    REQUIRE(speedMessage(psys_fire(s, "go", nullptr, 0)) == "");  // (restarts the system's own)
    for (int i = 0; i < 3; ++i) REQUIRE(speedMessage(psys_step(s, 0.1)) == "");
    auto dots = pacedPoints(s, 0);
    REQUIRE(dots.size() == 1);
    REQUIRE(dots.begin()->second.size() == 1);
    CHECK(dots.begin()->second[0][0] == doctest::Approx(0.3));  // aged 0.3 s: at 1, not paused nor at 3
    psys_system_free(s);
}
