// An ahead-of-time build plays instances at their own speeds as the JIT does, bit for bit
// in exact maths (tests/programs/paced.psys, built by psysc build at this test's build):
// the archive holds each update's form with a per-row dt (rt/system_speeds.cpp).
#define DOCTEST_CONFIG_IMPLEMENT_WITH_MAIN
#include <doctest/doctest.h>

#include <array>
#include <string>
#include <vector>

#include "aot_paced.h"
#include "psys/psys.h"

namespace {

std::string aotMessage(psys_error* e) {
    std::string m = e ? psys_error_message(e) : "";
    psys_error_free(e);
    return m;
}

// Every drawn column of every type, after a run that paces three instances.
std::vector<std::vector<float>> pacedRun(psys_system* s) {
    REQUIRE(aotMessage(psys_instance_kill(s, 0)) == "");
    std::vector<psys_instance> h(3);
    for (size_t i = 0; i < h.size(); ++i) {
        std::array<float, 16> m{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 3.0f * static_cast<float>(i), 0, 0, 1};
        REQUIRE(aotMessage(psys_play(s, m.data(), &h[i])) == "");
    }
    auto steps = [&](int n) {
        for (int i = 0; i < n; ++i) REQUIRE(aotMessage(psys_step(s, 1.0 / 60)) == "");
    };
    REQUIRE(aotMessage(psys_instance_set_speed(s, h[0], 0.3f)) == "");
    REQUIRE(aotMessage(psys_instance_set_speed(s, h[1], 2.5f)) == "");
    steps(20);
    REQUIRE(aotMessage(psys_instance_pause(s, h[2], 1)) == "");
    steps(20);
    REQUIRE(aotMessage(psys_instance_pause(s, h[2], 0)) == "");
    steps(20);
    std::vector<std::vector<float>> out;
    for (size_t type = 0; type < 3; ++type) {
        psys_draw d;
        REQUIRE(aotMessage(psys_get_draw(s, type, &d)) == "");
        for (const psys_column* c : {&d.visible, &d.position[0], &d.position[1], &d.position[2], &d.size, &d.instance}) {
            std::vector<float>& column = out.emplace_back();
            for (size_t r = 0; r < d.rows; ++r) column.push_back(c->data ? static_cast<const float*>(c->data)[r] : c->constant);
        }
    }
    return out;
}

}  // namespace

TEST_CASE("an ahead-of-time build plays instances at their own speeds as the JIT does, bit for bit") {
    psys_options o;
    psys_options_init(&o);
    o.math = "exact";
    o.threads = 1;
    psys_system* jit = nullptr;
    const std::string file = std::string(PSYS_PROGRAMS_DIR) + "/paced.psys";
    REQUIRE(aotMessage(psys_compile_file(file.c_str(), &o, &jit)) == "");
    o.backend = "aot";
    psys_system* aot = nullptr;
    REQUIRE(aotMessage(aot_paced_open(&o, &aot)) == "");
    auto a = pacedRun(jit), b = pacedRun(aot);
    CHECK(a[0].size() > 10);
    CHECK(a == b);
    psys_system_free(jit);
    psys_system_free(aot);
}
