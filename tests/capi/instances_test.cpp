// Instances through the C API (include/psys/psys.h, "Instances"): an effect played many
// times in one system — each instance's objects at its transform, in world or local
// space, stopped, killed, finished and reported once, its slot reused under a new handle;
// the same on the interpreter and the JIT; every bad call an error.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "psys/psys.h"

namespace {

std::string message(psys_error* e) {
    std::string m = e ? psys_error_message(e) : "";
    psys_error_free(e);
    return m;
}

struct Effect {
    psys_system* s = nullptr;
    Effect(const char* source, const char* backend, const char* math = "fast") {
        psys_options o;
        psys_options_init(&o);
        o.backend = backend;
        o.math = math;
        o.threads = 1;
        REQUIRE(message(psys_compile_string(source, "effect.psys", &o, &s)) == "");
    }
    ~Effect() { psys_system_free(s); }
    void step(int frames = 1) {
        for (int i = 0; i < frames; ++i) REQUIRE(message(psys_step(s, 1.0 / 60)) == "");
    }
};

// A hit: sparks thrown from where the instance is when they are made (world space: they
// stay behind when it moves), and a ring that follows it (local space).
const char* const kHit = R"(
object spark(v: vec3) {
    pos = snapshot(instance.pos) + integrate(v);
    point(pos, white, 2);
    kill when age > 0.5;
}
object ring(k: float) {
    pos = instance.pos + instance.x * cos(k) + instance.z * sin(k);
    point(pos, red, 1);
    kill when age > 1;
}
object hit {
    emit spark(nrand3()) at 120 per second;
    emit ring(rand() * tau) count 8;
    kill when age > 1;
}
trigger flash(n: float) { emit ring(n) count 2; }
spawn hit;
)";

std::array<float, 16> translation(float x, float y, float z) {
    return {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, x, y, z, 1};
}

// Per instance slot: the drawn rows of `type` (their positions).
std::map<int, std::vector<std::array<float, 3>>> rowsBySlot(psys_system* s, size_t type) {
    psys_draw d;
    REQUIRE(message(psys_get_draw(s, type, &d)) == "");
    std::map<int, std::vector<std::array<float, 3>>> out;
    auto value = [&](const psys_column& c, size_t r) { return c.data ? static_cast<const float*>(c.data)[r] : c.constant; };
    for (size_t r = 0; r < d.rows; ++r) {
        if (value(d.visible, r) == 0) continue;
        out[static_cast<int>(value(d.instance, r))].push_back({value(d.position[0], r), value(d.position[1], r),
                                                               value(d.position[2], r)});
    }
    return out;
}

}  // namespace

TEST_CASE("instances: each instance's objects are at its transform, in world or local space") {
    for (const char* backend : {"llvm", "interp"}) {
        CAPTURE(backend);
        Effect e(kHit, backend);
        REQUIRE(message(psys_instance_kill(e.s, 0)) == "");  // the host plays them all
        auto at10 = translation(10, 0, 0), at20 = translation(0, 20, 0);
        psys_instance a = 0, b = 0;
        REQUIRE(message(psys_play(e.s, at10.data(), &a)) == "");
        REQUIRE(message(psys_play(e.s, at20.data(), &b)) == "");
        CHECK(a != b);
        CHECK(psys_instance_count(e.s) == 3);  // the system's own until the step that finishes it
        e.step(10);
        CHECK(psys_instance_count(e.s) == 2);
        auto rings = rowsBySlot(e.s, 1);
        REQUIRE(rings.size() == 2);
        for (auto& [slot, rows] : rings) {
            CHECK(rows.size() == 8);
            const float cx = slot == static_cast<int>(a & 0xffffffffu) ? 10.0f : 0.0f;
            const float cy = slot == static_cast<int>(a & 0xffffffffu) ? 0.0f : 20.0f;
            for (auto& p : rows) CHECK(std::hypot(p[0] - cx, p[2]) == doctest::Approx(1).epsilon(1e-5));
            for (auto& p : rows) CHECK(p[1] == doctest::Approx(cy));
        }
        // Moved: the ring follows (local space), sparks made before stay behind (world space).
        auto moved = translation(10, 5, 0);
        REQUIRE(message(psys_instance_transform(e.s, a, moved.data())) == "");
        e.step();
        const int slot = static_cast<int>(a & 0xffffffffu);
        auto ringsNow = rowsBySlot(e.s, 1), sparksNow = rowsBySlot(e.s, 0);
        CHECK(ringsNow[slot].size() == 8);
        for (auto& p : ringsNow[slot]) CHECK(p[1] == doctest::Approx(5));
        size_t behind = 0, after = 0;
        for (auto& p : sparksNow[slot]) (std::abs(p[1]) < 2 ? behind : after)++;
        CHECK(behind > 0);  // (thrown at up to 1 m/s for at most 0.5 s: near y = 0)
        CHECK(after > 0);   // (the last step's, from y = 5)
    }
}

TEST_CASE("instances: stop lets its objects live out their lives, then it finishes, reported once") {
    Effect e(kHit, "llvm");
    REQUIRE(message(psys_instance_kill(e.s, 0)) == "");
    psys_instance a = 0, b = 0;
    REQUIRE(message(psys_play(e.s, nullptr, &a)) == "");
    REQUIRE(message(psys_play(e.s, nullptr, &b)) == "");
    e.step(6);
    REQUIRE(message(psys_instance_stop(e.s, a)) == "");
    CHECK(psys_instance_life(e.s, a) == PSYS_STOPPED);
    psys_type_stats before, after;
    REQUIRE(message(psys_get_type_stats(e.s, 0, &before)) == "");
    e.step(3);
    auto sparks = rowsBySlot(e.s, 0);
    REQUIRE(message(psys_get_type_stats(e.s, 0, &after)) == "");
    CHECK(after.created - before.created <= 8);  // b's alone: 120/s for 3 frames (a's stopped)
    CHECK(sparks.count(static_cast<int>(a & 0xffffffffu)) == 1);  // a's still alive
    std::vector<psys_instance> finished;
    for (int frame = 0; frame < 90 && finished.empty(); ++frame) {
        e.step();
        psys_instance out[4];
        size_t n = psys_finished_instances(e.s, out, 4);
        finished.assign(out, out + std::min<size_t>(n, 4));
    }
    REQUIRE(finished.size() == 1);
    CHECK(finished[0] == a);
    CHECK(psys_instance_life(e.s, a) == PSYS_FINISHED);
    CHECK(psys_instance_life(e.s, b) == PSYS_PLAYING);
    e.step();
    CHECK(psys_finished_instances(e.s, nullptr, 0) == 0);  // once
    // Its slot is played again under a new handle; the old one stays finished.
    psys_instance c = 0;
    REQUIRE(message(psys_play(e.s, nullptr, &c)) == "");
    CHECK((c & 0xffffffffu) == (a & 0xffffffffu));
    CHECK(c != a);
    CHECK(psys_instance_life(e.s, a) == PSYS_FINISHED);
    CHECK(message(psys_instance_stop(e.s, a)).find("has finished") != std::string::npos);
}

TEST_CASE("instances: kill takes its objects at the next step and creates nothing more") {
    Effect e(kHit, "interp");
    psys_instance a = 0;
    REQUIRE(message(psys_play(e.s, nullptr, &a)) == "");
    e.step(5);
    CHECK(rowsBySlot(e.s, 0).count(static_cast<int>(a & 0xffffffffu)) == 1);
    REQUIRE(message(psys_instance_kill(e.s, a)) == "");
    CHECK(psys_instance_life(e.s, a) == PSYS_KILLED);
    CHECK(message(psys_instance_fire(e.s, a, "flash", std::array<float, 1>{1}.data(), 1)).find("killed") !=
          std::string::npos);
    e.step();
    CHECK(rowsBySlot(e.s, 0).count(static_cast<int>(a & 0xffffffffu)) == 0);
    CHECK(rowsBySlot(e.s, 1).count(static_cast<int>(a & 0xffffffffu)) == 0);
    CHECK(rowsBySlot(e.s, 0).count(0) == 1);  // the system's own plays on
    CHECK(psys_instance_life(e.s, a) == PSYS_FINISHED);
}

TEST_CASE("instances: a trigger fired on an instance creates for it, and hosts see the trigger's own parameters") {
    Effect e(kHit, "llvm");
    psys_input in;
    REQUIRE(psys_trigger_info(e.s, 0, &in) == 0);
    CHECK(std::string(in.type) == "float");
    CHECK(in.values == 1);
    REQUIRE(message(psys_instance_kill(e.s, 0)) == "");
    e.step();
    auto far = translation(0, 0, 50);
    psys_instance a = 0;
    REQUIRE(message(psys_play(e.s, far.data(), &a)) == "");
    float n = 0;
    REQUIRE(message(psys_instance_fire(e.s, a, "flash", &n, 1)) == "");
    auto rings = rowsBySlot(e.s, 1);
    REQUIRE(rings.count(static_cast<int>(a & 0xffffffffu)) == 1);
    CHECK(rings[static_cast<int>(a & 0xffffffffu)].size() == 10);  // 8 of the hit, 2 of the flash
    for (auto& p : rings[static_cast<int>(a & 0xffffffffu)]) CHECK(p[2] == doctest::Approx(50).epsilon(0.05));
    CHECK(message(psys_instance_fire(e.s, a, "flash", &n, 2)).find("takes 1 number") != std::string::npos);
}

TEST_CASE("instances: the interpreter and the JIT's exact maths agree bit for bit") {
    auto run = [](const char* backend) {
        Effect e(kHit, backend, "exact");
        std::vector<psys_instance> played;
        for (int i = 0; i < 5; ++i) {
            auto m = translation(static_cast<float>(i), 0, static_cast<float>(-i));
            psys_instance h = 0;
            REQUIRE(message(psys_play(e.s, m.data(), &h)) == "");
            played.push_back(h);
            e.step(4);
            m[13] = 1;
            REQUIRE(message(psys_instance_transform(e.s, played[0], m.data())) == "");
        }
        REQUIRE(message(psys_instance_stop(e.s, played[1])) == "");
        e.step(20);
        return std::make_pair(rowsBySlot(e.s, 0), rowsBySlot(e.s, 1));
    };
    auto interp = run("interp"), jit = run("llvm");
    CHECK(interp.first.size() == 6);
    CHECK(interp == jit);
}

TEST_CASE("instances: bad calls are errors that change nothing") {
    Effect e(kHit, "llvm");
    psys_instance h = 0;
    std::array<float, 16> projective = translation(0, 0, 0);
    projective[11] = -1;
    CHECK(message(psys_play(e.s, projective.data(), &h)).find("affine") != std::string::npos);
    std::array<float, 16> nan = translation(NAN, 0, 0);
    CHECK(message(psys_play(e.s, nan.data(), &h)).find("finite") != std::string::npos);
    CHECK(psys_instance_count(e.s) == 1);
    CHECK(message(psys_play(e.s, nullptr, nullptr)).find("out") != std::string::npos);
    CHECK(message(psys_play(nullptr, nullptr, &h)).find("system") != std::string::npos);
    CHECK(message(psys_instance_stop(e.s, 77)).find("there is no instance 0x4d") != std::string::npos);
    CHECK(message(psys_instance_kill(e.s, uint64_t{5} << 32)).find("there is no instance") != std::string::npos);
    CHECK(psys_instance_life(e.s, 77) == PSYS_FINISHED);
    CHECK(psys_instance_life(nullptr, 0) == PSYS_FINISHED);
    CHECK(psys_finished_instances(nullptr, nullptr, 0) == 0);

    // A program that does not read `instance` could not tell its instances apart.
    Effect plain("object p { point(vec3(age), white, 1); } spawn p;", "llvm");
    CHECK(message(psys_play(plain.s, nullptr, &h)).find("not instanced") != std::string::npos);
    CHECK(message(psys_instance_stop(plain.s, 0)).find("not instanced") != std::string::npos);
    CHECK(psys_instance_count(plain.s) == 0);
    psys_draw d;
    plain.step();
    REQUIRE(message(psys_get_draw(plain.s, 0, &d)) == "");
    CHECK(d.instance.data == nullptr);
    CHECK(d.instance.constant == 0);
}

TEST_CASE("instances: the glsl backend refuses an instanced program with a worded error") {
    psys_options o;
    psys_options_init(&o);
    o.backend = "glsl";
    psys_system* s = nullptr;
    std::string m = message(psys_compile_string(kHit, "effect.psys", &o, &s));
    if (m.find("cannot start") != std::string::npos || m.find("EGL") != std::string::npos) return;  // no GL here
    CHECK(m.find("does not play instances yet") != std::string::npos);
    CHECK(m.find("internal error") == std::string::npos);
    CHECK(s == nullptr);
    psys_system_free(s);
}

TEST_CASE("instances: a hot reload keeps the instances playing where they were") {
    Effect e(kHit, "llvm");
    auto far = translation(30, 0, 0);
    psys_instance a = 0;
    REQUIRE(message(psys_play(e.s, far.data(), &a)) == "");
    e.step(5);
    std::string edited = kHit;
    edited.replace(edited.find("point(pos, red, 1)"), std::string("point(pos, red, 1)").size(), "point(pos, blue, 1)");
    REQUIRE(message(psys_reload(e.s, edited.c_str())) == "");
    CHECK(psys_instance_life(e.s, a) == PSYS_PLAYING);
    CHECK(psys_instance_count(e.s) == 2);
    e.step();
    auto rings = rowsBySlot(e.s, 1);
    REQUIRE(rings.count(static_cast<int>(a & 0xffffffffu)) == 1);
    for (auto& p : rings[static_cast<int>(a & 0xffffffffu)]) CHECK(std::abs(p[0] - 30) <= 1.0001f);
    auto moved = translation(-30, 0, 0);
    REQUIRE(message(psys_instance_transform(e.s, a, moved.data())) == "");
    e.step();
    rings = rowsBySlot(e.s, 1);
    for (auto& p : rings[static_cast<int>(a & 0xffffffffu)]) CHECK(std::abs(p[0] + 30) <= 1.0001f);
}

namespace {

// Shells thrown up that pop at 1 s, telling where (`on death`), and telling once when they
// pass 3 m; a trigger that notifies where it is fired.
const char* const kPops = R"(
object shell(v: vec3) {
    pos = integrate(v + integrate(vec3(0, -9.8, 0)));
    point(pos, white, 3);
    kill when age > 1;
    on death { notify "pop"(pos, age); }
    when pos.y > 3 { notify "high"(pos.y); }
}
object launcher { emit shell(vec3(nrand(), 8, nrand())) at 5 per second; }
trigger bang(where: point) { notify "pop"(where, 0); }
spawn launcher;
)";

std::vector<float> readEvents(psys_system* s, const char* name, size_t& width) {
    size_t n = 0;
    REQUIRE(message(psys_read_events(s, name, nullptr, 0, &n, &width)) == "");
    std::vector<float> out(n * width);
    REQUIRE(message(psys_read_events(s, name, out.data(), n, &n, &width)) == "");
    return out;
}

// Every "pop" of `frames` steps, step by step.
std::vector<std::vector<float>> popsOf(const char* backend, const char* math, int frames) {
    Effect e(kPops, backend, math);
    std::vector<std::vector<float>> out;
    for (int f = 0; f < frames; ++f) {
        e.step();
        size_t width = 0;
        out.push_back(readEvents(e.s, "pop", width));
        CHECK(width == 4);
    }
    return out;
}

}  // namespace

TEST_CASE("events: each notification read once, after its step, the same on every backend") {
    Effect e(kPops, "llvm");
    REQUIRE(psys_event_count(e.s) == 2);
    CHECK(std::string(psys_event_name(e.s, 0)) == "pop");
    CHECK(std::string(psys_event_name(e.s, 1)) == "high");
    CHECK(psys_event_name(e.s, 2) == nullptr);
    size_t pops = 0, highs = 0;
    for (int f = 0; f < 240; ++f) {
        e.step();
        size_t width = 0;
        std::vector<float> p = readEvents(e.s, "pop", width);
        REQUIRE(width == 4);
        for (size_t k = 0; k < p.size(); k += 4) {
            CHECK(p[k + 3] > 1.0f);                      // its age at death
            // (the integrator's: within g·t·dt/2 of the closed form)
            CHECK(std::abs(p[k + 1] - (8 * p[k + 3] - 4.9f * p[k + 3] * p[k + 3])) < 0.1f);
        }
        pops += p.size() / 4;
        highs += readEvents(e.s, "high", width).size();
        CHECK(width == 1);
    }
    psys_type_stats shells;
    REQUIRE(message(psys_get_type_stats(e.s, 0, &shells)) == "");
    CHECK(pops == shells.killed);  // once each
    // Each shell passes 3 m once, 0.46 s after it is thrown: every dead one has, and at
    // most the live ones besides (5 a second, living a second).
    CHECK(highs >= pops);
    CHECK(highs <= pops + shells.live);
    CHECK(highs < shells.created);
    // A trigger's: readable at once, gone after the next step.
    float at[3] = {1, 2, 3};
    REQUIRE(message(psys_fire(e.s, "bang", at, 3)) == "");
    size_t width = 0;
    std::vector<float> now = readEvents(e.s, "pop", width);
    bool found = false;
    for (size_t k = 0; k < now.size(); k += 4) found |= now[k] == 1 && now[k + 1] == 2 && now[k + 2] == 3;
    CHECK(found);
    CHECK(message(psys_read_events(e.s, "boom", nullptr, 0, nullptr, nullptr)).find("its events are \"pop\", \"high\"") !=
          std::string::npos);
    CHECK(message(psys_read_events(e.s, nullptr, nullptr, 0, nullptr, nullptr)).find("name") != std::string::npos);

    auto interp = popsOf("interp", "exact", 150);
    CHECK(interp == popsOf("llvm", "exact", 150));
    psys_options o;
    psys_options_init(&o);
    o.backend = "glsl";
    psys_system* gpu = nullptr;
    std::string m = message(psys_compile_string(kPops, "pops.psys", &o, &gpu));
    psys_system_free(gpu);
    if (m.find("cannot start") != std::string::npos || m.find("EGL") != std::string::npos) return;  // no GL here
    auto glsl = popsOf("glsl", "exact", 150);
    REQUIRE(glsl.size() == interp.size());
    for (size_t f = 0; f < glsl.size(); ++f) {
        REQUIRE(glsl[f].size() == interp[f].size());
        for (size_t k = 0; k < glsl[f].size(); ++k) CHECK(glsl[f][k] == doctest::Approx(interp[f][k]).epsilon(1e-5));
    }
}

TEST_CASE("events: an instanced program's end with the instance") {
    std::string source = std::string(kPops);
    source.replace(source.find("point(pos, white, 3);"), std::string("point(pos, white, 3);").size(),
                   "point(instance.pos + pos, white, 3);");
    Effect e(source.c_str(), "llvm");
    psys_instance a = 0;
    REQUIRE(message(psys_play(e.s, nullptr, &a)) == "");
    size_t seen0 = 0, seenA = 0;
    for (int f = 0; f < 120; ++f) {
        e.step();
        size_t width = 0;
        std::vector<float> p = readEvents(e.s, "pop", width);
        REQUIRE(width == 5);
        for (size_t k = 0; k < p.size(); k += 5) {
            CHECK((p[k + 4] == 0 || p[k + 4] == static_cast<float>(a & 0xffffffffu)));
            (p[k + 4] == 0 ? seen0 : seenA) += 1;
        }
    }
    CHECK(seen0 > 0);
    CHECK(seenA > 0);
}

TEST_CASE("instances: each reads its own externs — the effect's until the host sets one's") {
    const char* const source = R"(
extern radius: float = 1 range(0, 10);
extern lift: float = 0;
extern lit: bool = true;
object ring(k: float) {
    pos = instance.pos + vec3(cos(k), 0, sin(k)) * radius + vec3(0, lift, 0);
    point(pos, red, 1);
    kill when age > 1 || !lit;
}
object hit {
    emit ring(rand() * tau) count 8;
    kill when age > 1;
}
trigger more(k: float) { emit ring(k) count radius; }
spawn hit;
)";
    std::map<std::string, std::vector<float>> drawn;  // per backend: every row's y and distance
    for (const char* backend : {"llvm", "interp"}) {
        CAPTURE(backend);
        Effect e(source, backend, "exact");
        REQUIRE(message(psys_instance_kill(e.s, 0)) == "");
        auto at0 = translation(0, 0, 0), at50 = translation(50, 0, 0);
        psys_instance a = 0, b = 0;
        REQUIRE(message(psys_play(e.s, at0.data(), &a)) == "");
        REQUIRE(message(psys_play(e.s, at50.data(), &b)) == "");
        const float two = 2, three = 3, five = 5, no = 0;
        REQUIRE(message(psys_instance_set_extern(e.s, a, "radius", &two, 1)) == "");
        float got[4] = {};
        CHECK(psys_instance_get_extern(e.s, a, "radius", got) == 1);
        CHECK(got[0] == 2);
        CHECK(psys_instance_get_extern(e.s, b, "radius", got) == 1);
        CHECK(got[0] == 1);
        CHECK(psys_get_extern(e.s, "radius", got) == 1);
        CHECK(got[0] == 1);  // (the effect's)
        REQUIRE(message(psys_set_extern(e.s, "lift", &three, 1)) == "");  // every instance's
        e.step();
        auto distances = [&](int slot, float cx) {
            std::vector<float> out;
            auto rows = rowsBySlot(e.s, 0);
            for (auto& p : rows[slot]) {
                CHECK(p[1] == doctest::Approx(3));
                out.push_back(std::hypot(p[0] - cx, p[2]));
            }
            return out;
        };
        const int sa = static_cast<int>(a & 0xffffffffu), sb = static_cast<int>(b & 0xffffffffu);
        auto da = distances(sa, 0), db = distances(sb, 50);
        CHECK(da.size() == 8);
        CHECK(db.size() == 8);
        for (float d : da) CHECK(d == doctest::Approx(2).epsilon(1e-5));
        for (float d : db) CHECK(d == doctest::Approx(1).epsilon(1e-5));
        // A trigger on one instance reads its values: `count radius`.
        REQUIRE(message(psys_instance_fire(e.s, a, "more", &no, 1)) == "");
        REQUIRE(message(psys_instance_fire(e.s, b, "more", &no, 1)) == "");
        e.step();
        CHECK(rowsBySlot(e.s, 0)[sa].size() == 10);
        CHECK(rowsBySlot(e.s, 0)[sb].size() == 9);
        // A hot reload keeps each instance's values.
        REQUIRE(message(psys_reload(e.s, source)) == "");
        CHECK(psys_instance_get_extern(e.s, a, "radius", got) == 1);
        CHECK(got[0] == 2);
        // A bool of one instance's: b's rings die, a's live on.
        REQUIRE(message(psys_instance_set_extern(e.s, b, "lit", &no, 1)) == "");
        e.step();
        CHECK(rowsBySlot(e.s, 0)[sa].size() == 10);
        CHECK(rowsBySlot(e.s, 0).count(sb) == 0);
        for (float d : distances(sa, 0)) drawn[backend].push_back(d);
        // The effect's value sets every instance's; a new one starts with the effect's.
        REQUIRE(message(psys_set_extern(e.s, "radius", &five, 1)) == "");
        CHECK(psys_instance_get_extern(e.s, a, "radius", got) == 1);
        CHECK(got[0] == 5);
        psys_instance c = 0;
        REQUIRE(message(psys_play(e.s, nullptr, &c)) == "");
        CHECK(psys_instance_get_extern(e.s, c, "lit", got) == 1);
        CHECK(got[0] == 1);
        // Refusals, in words, changing nothing.
        CHECK(message(psys_instance_set_extern(e.s, a, "nope", &two, 1)) ==
              "psys_instance_set_extern: there is no extern `nope`");
        const float eleven = 11, half = 0.5f;
        CHECK(message(psys_instance_set_extern(e.s, a, "radius", &eleven, 1)) ==
              "psys_instance_set_extern: extern `radius`: 11 is outside its range [0, 10]; it keeps its value");
        CHECK(message(psys_instance_set_extern(e.s, a, "lit", &half, 1)).find("is a bool") != std::string::npos);
        CHECK(message(psys_instance_set_extern(e.s, a, "radius", got, 2)).find("takes 1 value, not 2") != std::string::npos);
        CHECK(message(psys_instance_set_extern(e.s, a, "radius", nullptr, 1)) ==
              "psys_instance_set_extern: the values is NULL");
        REQUIRE(message(psys_instance_kill(e.s, b)) == "");
        e.step();
        CHECK(message(psys_instance_set_extern(e.s, b, "radius", &two, 1)).find("has finished") != std::string::npos);
        CHECK(psys_instance_get_extern(e.s, b, "radius", got) == -1);
        CHECK(psys_instance_get_extern(e.s, a, "nope", got) == -1);
        CHECK(psys_instance_get_extern(e.s, a, "radius", got) == 1);
        CHECK(got[0] == 5);
    }
    CHECK(drawn["llvm"] == drawn["interp"]);  // (exact maths: the same bits)
}
