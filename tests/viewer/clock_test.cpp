// The viewer's clock (tools/viewer/sim_clock.h) under fake wall-clock times — N seconds of
// frames at any rate are N simulated seconds in steps of one size; a stall's catch-up is
// capped and counted; a fixed clock runs a step a frame — and the viewer run by a fake
// clock. With them, the keys written once (tools/viewer/keys.h) and the panel's font.
#include <doctest/doctest.h>

#include <cmath>
#include <fstream>
#include <random>
#include <sstream>

#include "keys.h"
#include "panel.h"
#include "sim_clock.h"
#include "viewer.h"

using namespace psys;
using namespace psys::viewer;

TEST_CASE("real time: N wall-clock seconds of uneven frames are N simulated seconds, in whole fixed steps") {
    for (double fps : {30.0, 59.0, 60.0, 144.0, 240.0, 1000.0}) {
        SimClock clock;
        std::mt19937 random(7);
        std::uniform_real_distribution<double> jitter(0.5, 1.5);  // each frame 0.5–1.5× the mean
        double wall = 0;
        while (wall < 10) {
            double frame = jitter(random) / fps;
            wall += frame;
            int steps = clock.advance(frame);
            CHECK(steps >= 0);
            CHECK(steps <= 8);
        }
        CAPTURE(fps);
        // Behind real time by less than one step; never ahead.
        CHECK(clock.simulated() <= wall + 1e-9);
        CHECK(clock.simulated() > wall - 1.0 / 60);
        CHECK(clock.steps() == static_cast<uint64_t>(std::llround(clock.simulated() * 60)));
        CHECK(clock.cappedFrames() == 0);
    }
}

TEST_CASE("real time: frames of exactly one step run one step each, whatever the rounding") {
    SimClock clock;
    for (int f = 0; f < 6000; ++f) REQUIRE(clock.advance(1.0 / 60) == 1);
    CHECK(clock.steps() == 6000);
}

TEST_CASE("real time: a stall runs at most maxSteps, and the time let go is counted") {
    SimClock clock({1.0 / 60, false, 1, 8});
    CHECK(clock.advance(1.0 / 60) == 1);
    CHECK(clock.advance(5.0) == 8);  // 300 steps owed
    CHECK(clock.cappedFrames() == 1);
    CHECK(clock.dropped() == doctest::Approx(5.0 - 8.0 / 60).epsilon(1e-9));
    CHECK(clock.advance(1.0 / 60) == 1);  // and then real time again, nothing owed
    CHECK(clock.simulated() + clock.dropped() == doctest::Approx(1.0 / 60 + 5.0 + 1.0 / 60));
}

TEST_CASE("real time: the time scale runs more steps of the same size, not longer steps") {
    SimClock clock({1.0 / 60, false, 2, 8});
    double wall = 0;
    for (int f = 0; f < 600; ++f, wall += 1.0 / 60) clock.advance(1.0 / 60);
    CHECK(clock.stepSeconds() == doctest::Approx(1.0 / 60));
    CHECK(clock.simulated() == doctest::Approx(2 * wall).epsilon(1e-6));
}

TEST_CASE("fixed: a step a frame, scaled, however long the frame took") {
    SimClock clock({0.01, true, 0.5, 8});
    for (double frame : {0.0, 0.001, 3.0, 0.5}) CHECK(clock.advance(frame) == 1);
    CHECK(clock.stepSeconds() == doctest::Approx(0.005));
    CHECK(clock.simulated() == doctest::Approx(0.02));
    CHECK(clock.cappedFrames() == 0);
    clock.settings().fixed = false;  // T: real time from here, nothing owed from before
    clock.resetDebt();
    CHECK(clock.advance(0.01) == 0);  // half a step of 0.01 s at half speed…
    CHECK(clock.advance(0.01) == 1);  // …and the other half
    CHECK(clock.stepSeconds() == doctest::Approx(0.01));
}

namespace {

// A viewer drawing offscreen (64×64) on `text`, headless, not watching; `options` says the rest.
struct Offscreen {
    std::unique_ptr<Surface> surface;
    std::unique_ptr<Viewer> viewer;
};

Offscreen viewerOn(const std::string& text, ViewerOptions options) {
    Offscreen out;
    std::string error;
    out.surface = openOffscreen(64, 64, error);
    REQUIRE_MESSAGE(out.surface, error);
    options.file = "test.psys";
    options.headless = true;
    options.watch = false;
    host::CompileResult compiled;
    auto session = host::Session::open(options.file, options.session, compiled, error, &text);
    REQUIRE_MESSAGE(session, compiled.text(), error);
    out.viewer = std::make_unique<Viewer>(options, *out.surface, std::move(session), compiled);
    return out;
}

}  // namespace

TEST_CASE("the viewer in real time: 5 seconds of a fake wall clock at 144 frames a second are 5 simulated seconds") {
    ViewerOptions options;
    options.frames = 720;  // 5 s at 144 fps
    options.ui = false;
    options.fixed = false;
    Clock::time_point fake{};
    options.now = [&] { return fake += std::chrono::microseconds(6944); };  // 1/144 s a frame
    Offscreen o = viewerOn("object p { point(vec3(0), white, 1); }\nspawn p;", options);
    Viewer& viewer = *o.viewer;
    CHECK(viewer.run() == 0);
    double wall = 720 * 6944e-6;
    CHECK(viewer.session().system().time() <= wall + 1e-9);
    CHECK(viewer.session().system().time() > wall - 1.0 / 60);
    CHECK(viewer.clock().steps() == static_cast<uint64_t>(std::floor(wall * 60 + 1e-9)));
}

TEST_CASE("docs/viewer.md's table of keys is the viewer's (psys-view --keys)") {
    std::ifstream in(PSYS_DOCS_DIR "/viewer.md");
    std::stringstream docs;
    docs << in.rdbuf();
    std::string text = docs.str();
    const std::string open = "<!-- psys-view --keys -->\n", close = "<!-- end of psys-view --keys -->";
    size_t begin = text.find(open), end = text.find(close);
    REQUIRE(begin != std::string::npos);
    REQUIRE(end != std::string::npos);
    begin += open.size();
    CHECK(text.substr(begin, end - begin) == keysMarkdown());
}

TEST_CASE("every key a script names is a key of the table, and none is named twice") {
    std::set<std::string> names;
    for (const KeyBinding& b : keyBindings())
        for (const KeyPress& p : b.presses) {
            CHECK(names.insert(p.name).second);
            CHECK(keyPress(p.name)->code == p.code);
        }
    CHECK(names.count("F1"));
    CHECK(keyPress("?")->shift);
    CHECK(!keyPress("f1"));
}

TEST_CASE("the panel's font draws the text it writes beyond ASCII") {
    Offscreen o = viewerOn("object p { point(vec3(0), white, 1); }", ViewerOptions{});
    Viewer& viewer = *o.viewer;
    REQUIRE(viewer.panel());
    CHECK(viewer.run() == 0);  // a frame, so that the font atlas is built
    for (unsigned c : {0x2026u /* … */, 0x2013u /* – */, 0x00D7u /* × */, 0x00F7u /* ÷ */, 0x2264u /* ≤ */, 0x03BCu /* μ */})
        CHECK_MESSAGE(viewer.panel()->hasGlyph(c), "U+" << std::hex << c);
}
