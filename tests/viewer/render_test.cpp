// The viewer's drawing, offscreen (EGL surfaceless: Mesa's llvmpipe where there is no
// GPU), checked by what a drawing must show: a point's colour where it projects, nothing
// where nothing is, the two blending modes, a sample's particles where they are — not by
// a golden image.
#define DOCTEST_CONFIG_IMPLEMENT_WITH_MAIN
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <filesystem>
#include <fstream>

#include "viewer.h"

using namespace psys;
using namespace psys::viewer;

namespace {

constexpr int kWidth = 320, kHeight = 240;

struct Pixel {
    int r, g, b;
};

struct Frame {
    std::vector<uint8_t> rgba;
    Pixel at(int x, int y) const {
        size_t i = (static_cast<size_t>(y) * kWidth + static_cast<size_t>(x)) * 4;
        return {rgba[i], rgba[i + 1], rgba[i + 2]};
    }
};

// The background's colour (render.cpp's clearFrame) in 8 bits.
const Pixel kBackground{9, 10, 14};

bool background(Pixel p) {
    return std::abs(p.r - kBackground.r) <= 1 && std::abs(p.g - kBackground.g) <= 1 && std::abs(p.b - kBackground.b) <= 1;
}

// Runs `text` for `frames` frames offscreen, no grid, and returns the last frame; `check`
// sees the viewer (its system and camera) before it goes.
Frame render(const std::string& text, int frames, Blend blend, const std::function<void(Viewer&)>& check = {},
             const std::string& backend = "llvm", const std::function<void(Viewer&)>& setup = {}) {
    std::string error;
    auto surface = openOffscreen(kWidth, kHeight, error);
    REQUIRE_MESSAGE(surface, error);
    ViewerOptions options;
    options.file = "test.psys";
    options.headless = true;
    options.frames = frames;
    options.grid = false;
    options.ui = false;
    options.watch = false;
    options.blend = blend;
    options.glow.on = false;  // colours as given (the glow's own tests turn it on)
    options.camera = Camera::parse("0,0,10,0,2,0");  // from +z, level, looking at (0, 2, 0)
    options.session.backend.name = backend;
    host::CompileResult compiled;
    auto session = host::Session::open("test.psys", options.session, compiled, error, &text);
    REQUIRE_MESSAGE(session, compiled.text(), error);
    Viewer viewer(options, *surface, std::move(session), compiled);
    if (setup) setup(viewer);
    CHECK(viewer.run() == 0);
    if (check) check(viewer);
    return {surface->pixels()};
}

// Where a point projects in the frame (pixels, top row 0), if it does.
std::optional<std::pair<int, int>> project(const Camera& camera, glm::vec3 p) {
    glm::vec4 clip = camera.projection(static_cast<float>(kWidth) / kHeight) * camera.view() * glm::vec4(p, 1);
    if (clip.w <= 0) return std::nullopt;
    glm::vec3 ndc = glm::vec3(clip) / clip.w;
    int x = static_cast<int>(std::floor((ndc.x * 0.5f + 0.5f) * kWidth));
    int y = static_cast<int>(std::floor((1 - (ndc.y * 0.5f + 0.5f)) * kHeight));
    if (x < 0 || y < 0 || x >= kWidth || y >= kHeight) return std::nullopt;
    return std::pair{x, y};
}

}  // namespace

TEST_CASE("a point is drawn in its colour where it projects, and nowhere else") {
    Frame f = render("object p { point(vec3(0, 2, 0), red, 8); }\nspawn p;", 1, Blend::Additive);
    // (0, 2, 0) is what the camera looks at: the middle of the frame.
    Pixel middle = f.at(kWidth / 2, kHeight / 2);
    CHECK(middle.r >= 250);
    CHECK(middle.g <= 20);
    CHECK(middle.b <= 20);
    CHECK(background(f.at(kWidth / 2 + 40, kHeight / 2)));
    CHECK(background(f.at(10, 10)));
    size_t lit = 0;
    for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x) lit += !background(f.at(x, y));
    // A disc 8 pixels across at the reference distance, 16·(240/720)… at distance 10: a few dozen pixels.
    CHECK(lit > 4);
    CHECK(lit < 400);
}

TEST_CASE("a type hidden is not drawn, and a solo type is drawn alone") {
    std::string text = "object a { point(vec3(0, 2, 0), red, 8); }\n"
                       "object b { point(vec3(2, 2, 0), green, 8); }\nspawn a; spawn b;";
    // (2, 2, 0) lies right of the middle, on the same row.
    auto lit = [](const Frame& f, int x0, int x1) {
        size_t n = 0;
        for (int x = x0; x < x1; ++x) n += !background(f.at(x, kHeight / 2));
        return n;
    };
    int middle = kWidth / 2, right = middle + 30;  // a's disc, b's disc: between them, the background
    Frame both = render(text, 1, Blend::Additive);
    REQUIRE(lit(both, middle - 3, middle + 4) > 0);
    REQUIRE(lit(both, right, kWidth) > 0);
    Frame hidden = render(text, 1, Blend::Additive, {}, "llvm", [](Viewer& v) { v.hide("b", true); });
    CHECK(lit(hidden, middle - 3, middle + 4) > 0);
    CHECK(lit(hidden, right, kWidth) == 0);
    Frame solo = render(text, 1, Blend::Additive, {}, "llvm", [](Viewer& v) { v.solo("b"); });
    CHECK(lit(solo, 0, right) == 0);
    CHECK(lit(solo, right, kWidth) > 0);
    Frame shownAgain = render(text, 1, Blend::Additive, {}, "llvm", [](Viewer& v) {
        v.hide("b", true);
        v.hide("b", false);
    });
    CHECK(shownAgain.rgba == both.rgba);
}

TEST_CASE("nothing is drawn for a system without objects") {
    Frame f = render("object p { point(vec3(0, 2, 0), red, 8); }", 3, Blend::Additive);
    for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x) REQUIRE(background(f.at(x, y)));
}

TEST_CASE("blending: alpha draws later points over earlier ones, additive sums them") {
    std::string text = "object a { point(vec3(0, 2, 0), vec4(1, 0, 0, 0.5), 8); }\n"
                       "object b { point(vec3(0, 2, 0), vec4(0, 1, 0, 0.5), 8); }\nspawn a; spawn b;";
    auto near = [](int value, double expected) { return std::abs(value - expected) <= 6; };
    Pixel over = render(text, 1, Blend::Alpha).at(kWidth / 2, kHeight / 2);
    // red over the background by half, then green over that by half
    double r = 0.5 * (0.5 * 255 + 0.5 * kBackground.r), g = 0.5 * 255 + 0.5 * (0.5 * kBackground.g),
           b = 0.5 * (0.5 * kBackground.b);
    CHECK(near(over.r, r));
    CHECK(near(over.g, g));
    CHECK(near(over.b, b));
    Pixel sum = render(text, 1, Blend::Additive).at(kWidth / 2, kHeight / 2);
    CHECK(near(sum.r, kBackground.r + 127.5));
    CHECK(near(sum.g, kBackground.g + 127.5));
    CHECK(near(sum.b, kBackground.b));
}

TEST_CASE("a sample's particles are drawn where they project") {
    std::ifstream in(std::string(PSYS_SAMPLES_DIR) + "/fountain.psys");
    std::string text((std::istreambuf_iterator<char>(in)), {});
    std::vector<std::pair<int, int>> where;
    Frame f = render(text, 90, Blend::Additive, [&](Viewer& viewer) {
        Camera camera = viewer.camera();
        for (const rt::RenderPoint& p : viewer.session().system().points(0))
            if (auto xy = project(camera, {p.position[0], p.position[1], p.position[2]})) where.push_back(*xy);
    });
    REQUIRE(where.size() > 500);
    size_t lit = 0;
    for (auto [x, y] : where) lit += !background(f.at(x, y));
    CHECK(lit >= where.size() * 95 / 100);
}

TEST_CASE("the GLSL backend computes in the viewer's own GL context and draws what the JIT draws") {
    std::ifstream in(std::string(PSYS_SAMPLES_DIR) + "/fountain.psys");
    std::string text((std::istreambuf_iterator<char>(in)), {});
    size_t drawn = 0;
    Frame gpu = render(text, 90, Blend::Additive, [&](Viewer& viewer) {
        CHECK(viewer.session().backend().name() == "glsl");
        drawn = viewer.session().system().points(0).size();
    }, "glsl");
    Frame jit = render(text, 90, Blend::Additive, {}, "llvm");
    CHECK(drawn > 500);
    // The fountain's values agree to a few ulp (tests/gpu): at most a pixel here and there
    // differs, where a point's edge falls on a pixel's edge.
    REQUIRE(gpu.rgba.size() == jit.rgba.size());
    size_t differ = 0;
    for (size_t i = 0; i < gpu.rgba.size(); i += 4) differ += std::memcmp(&gpu.rgba[i], &jit.rgba[i], 4) != 0;
    MESSAGE(differ << " of " << gpu.rgba.size() / 4 << " pixels differ");
    CHECK(differ <= gpu.rgba.size() / 4 / 1000);
}
