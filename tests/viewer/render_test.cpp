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
#include <map>

#include <fmt/format.h>
#include <stb_image_write.h>

#include "gpu/glsl_backend.h"
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
             const std::string& backend = "llvm", const std::function<void(Viewer&)>& setup = {},
             const std::function<void(ViewerOptions&)>& configure = {}) {
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
    if (configure) configure(options);
    host::CompileResult compiled;
    auto session = host::Session::open(options.file, options.session, compiled, error, &text);
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

// ---------------------------------------------------------------- sprites, streaks, glow

namespace {

std::string readText(const std::string& path) {
    std::ifstream in(path);
    return std::string((std::istreambuf_iterator<char>(in)), {});
}

size_t litPixels(const Frame& f) {
    size_t lit = 0;
    for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x) lit += !background(f.at(x, y));
    return lit;
}

size_t differentPixels(const Frame& a, const Frame& b) {
    REQUIRE(a.rgba.size() == b.rgba.size());
    size_t differ = 0;
    for (size_t i = 0; i < a.rgba.size(); i += 4)
        for (size_t c = 0; c < 3; ++c) {
            if (std::abs(int(a.rgba[i + c]) - int(b.rgba[i + c])) > 2) {
                ++differ;
                break;
            }
        }
    return differ;
}

}  // namespace

TEST_CASE("every sample is drawn: frame 600, fitted, lights its share of the frame, the same on every run") {
    // The least share of lit pixels each sample must show (about half of what it shows):
    // nothing blank, nothing lost off screen.
    const std::map<std::string, double> least = {
        {"bouncing", 0.04},     {"campfire", 0.02},  {"comet", 0.1},      {"composite_bounce", 0.002},
        {"confetti", 0.01},
        {"emitter", 0.01},      {"fire", 0.02},      {"fireworks", 0.004}, {"first_particle", 0.02},
        {"follow_parent", 0.004}, {"fountain", 0.004}, {"galaxy", 0.01},   {"grinder", 0.004},
        {"rain", 0.002},        {"random", 0.02},    {"smoke", 0.05},     {"swamp", 0.002},
        {"triggered_explosion", 0.01}, {"two_streams", 0.01}, {"wand", 0.1}, {"wind", 0.02},
        {"shapes", 0.03}, {"tornado", 0.1}, {"marbles", 0.03}, {"boids", 0.005}, {"repel", 0.4}, {"fluid", 0.2},
        {"predators", 0.005}};
    size_t samples = 0;
    for (auto& entry : std::filesystem::directory_iterator(PSYS_SAMPLES_DIR)) {
        if (entry.path().extension() != ".psys") continue;
        std::string name = entry.path().stem().string();
        INFO(name);
        REQUIRE_MESSAGE(least.count(name), "a new sample needs its share in this table");
        std::string text = readText(entry.path().string());
        auto configure = [&](ViewerOptions& o) {
            o.file = entry.path().string();  // (its textures are beside it)
            o.fit = true;
            o.glow.on = true;
            std::string script = std::string(PSYS_DOCS_DIR) + "/gallery/" + name + ".script";
            if (std::filesystem::exists(script)) {
                std::string error;
                auto parsed = Script::parse(readText(script), script, error);
                REQUIRE_MESSAGE(parsed, error);
                o.script = *parsed;
            }
        };
        Frame a = render(text, 600, Blend::Additive, {}, "llvm", {}, configure);
        Frame b = render(text, 600, Blend::Additive, {}, "llvm", {}, configure);
        double share = static_cast<double>(litPixels(a)) / (kWidth * kHeight);
        MESSAGE(name << ": " << share * 100 << "% lit");
        CHECK(share >= least.at(name));
        CHECK(a.rgba == b.rgba);
        ++samples;
    }
    CHECK(samples == least.size());
}

TEST_CASE("a sprite is as wide as its size in world units, at any distance") {
    for (float z : {0.0f, -10.0f}) {
        INFO("z " << z);
        std::string text = fmt::format("@shape(disc) object s {{ sprite(vec3(0, 2, {}), white, 2); }}\nspawn s;", z);
        Camera camera = *Camera::parse("0,0,10,0,2,0");
        auto left = project(camera, {-1, 2, z}), right = project(camera, {1, 2, z});
        REQUIRE(left);
        REQUIRE(right);
        Frame f = render(text, 1, Blend::Additive);
        int first = kWidth, last = -1, row = kHeight / 2;
        for (int x = 0; x < kWidth; ++x)
            if (!background(f.at(x, row))) {
                first = std::min(first, x);
                last = std::max(last, x);
            }
        CHECK(std::abs(first - left->first) <= 2);
        CHECK(std::abs(last - right->first) <= 2);
    }
}

TEST_CASE("a streak is drawn from its start to its end, as wide as its width") {
    Frame f = render("object s { streak(vec3(-2, 2, 0), vec3(2, 2, 0), white, 0.3); }\nspawn s;", 1, Blend::Additive);
    Camera camera = *Camera::parse("0,0,10,0,2,0");
    for (float x : {-1.8f, -1.0f, 0.0f, 1.0f, 1.8f}) {
        auto at = project(camera, {x, 2, 0});
        REQUIRE(at);
        CHECK_FALSE(background(f.at(at->first, at->second)));
    }
    for (glm::vec3 off : {glm::vec3(0, 2.6f, 0), glm::vec3(0, 1.4f, 0), glm::vec3(2.6f, 2, 0), glm::vec3(-2.6f, 2, 0)}) {
        auto at = project(camera, off);
        REQUIRE(at);
        CHECK(background(f.at(at->first, at->second)));
    }
}

TEST_CASE("a trail is a ribbon through the object's last positions, widest at its head, gone past its tail") {
    // Moving along x at 6 units a second: after 60 updates of 1/60 s its head is at x = 3,
    // its 31 points reach back 30 updates (0.5 s, 3 units) to x = 0.
    Frame f = render("object s { trail(vec3(-3 + age * 6, 2, 0), white, 0.5, 31); }\nspawn s;", 60, Blend::Additive);
    Camera camera = *Camera::parse("0,0,10,0,2,0");
    auto pixel = [&](float x, float y) {
        auto at = project(camera, {x, y, 0});
        REQUIRE(at);
        return f.at(at->first, at->second);
    };
    for (float x : {0.4f, 1.5f, 2.8f}) CHECK_FALSE(background(pixel(x, 2)));
    for (float x : {-0.4f, 3.4f}) CHECK(background(pixel(x, 2)));
    auto height = [&](float x) {  // the lit pixels across the ribbon at x
        auto at = project(camera, {x, 2, 0});
        int lit = 0;
        for (int y = 0; y < kHeight; ++y) lit += !background(f.at(at->first, y));
        return lit;
    };
    MESSAGE("lit pixels across the ribbon near its head " << height(2.8f) << ", near its tail " << height(0.4f));
    CHECK(height(2.8f) > 2 * height(0.4f));
    // Brighter at its head than near its tail: it fades.
    CHECK(pixel(2.8f, 2).r > pixel(0.4f, 2).r);
}

TEST_CASE("trails draw the same pixels from the JIT and from the GLSL backend, sorted on the GPU with nothing read back") {
    std::string text = R"(
        object a(p: vec3, v: vec3) { pos = p + integrate(v + vec3(0, -2, 0) * age); trail(pos, vec4(1, 0.6, 0.2, 1), 0.2, 24); kill when age > 1.5; }
        @blend(alpha) object b(p: vec3, v: vec3) { pos = p + integrate(v); trail(pos, vec4(0.3, 0.6, 1, 0.8), 0.4, 12); kill when age > 1.5; }
        object g {
            emit a(vec3(0, 2, 0), nrand3() * 3) at 40 per second;
            emit b(nrand3() + vec3(0, 2, 0), nrand3() * 2) at 40 per second;
        }
        spawn g;)";
    uint64_t waits = ~0ull, moved = 0;
    Frame gpu = render(text, 60, Blend::Additive, [&](Viewer& v) {
        // Drawing a frame more waits for nothing from the GPU: the points behind each head
        // are packed there (what it sends are the rows created this step, not yet sent).
        auto& gl = dynamic_cast<gpu::GlslBackend&>(v.session().backend());
        uint64_t before = gl.waits(), sent = gl.transferredBytes();
        v.draw();
        waits = gl.waits() - before;
        moved = gl.transferredBytes() - sent;
    }, "glsl");
    Frame jit = render(text, 60, Blend::Additive, {}, "llvm");
    size_t lit = litPixels(jit), differ = differentPixels(gpu, jit);
    MESSAGE(differ << " of " << lit << " lit pixels differ by more than 2 levels; drawing a frame waited " << waits
                   << " times for the GPU and sent it " << moved << " bytes");
    CHECK(lit > 3000);
    CHECK(differ <= lit / 100);
    CHECK(waits == 0);
}

TEST_CASE("sprites of every shape and streaks draw the same pixels from the JIT and from the GLSL backend") {
    std::string text = R"(
        @shape(soft) object a(p: vec3) { sprite(p + vec3(0, age, 0), vec4(1, 0.5, 0.2, 1), 0.6, age); kill when age > 1; }
        @shape(ring) object b(p: vec3) { sprite(p, vec4(0.3, 0.6, 1, 0.8), 0.5, age * 3); kill when age > 1; }
        @shape(star) object c(p: vec3) { sprite(p, vec4(2, 2, 1.5, 1), 0.8, age); kill when age > 1; }
        @shape(smoke) @blend(alpha) object d(p: vec3) { sprite(p, vec4(0.6, 0.6, 0.6, 0.5), 1, 0, 3); kill when age > 1; }
        @shape(disc) object e(p: vec3) { sprite(p, vec4(0.2, 1, 0.3, 1), 0.3); kill when age > 1; }
        object f(p: vec3, v: vec3) { pos = p + integrate(v); streak(pos - v * 0.1, pos, vec4(1, 0.8, 0.3, 1), 0.05); kill when age > 1; }
        object g {
            emit a(nrand3() * 2 + vec3(0, 2, 0)) at 20 per second;
            emit b(nrand3() * 2 + vec3(0, 2, 0)) at 20 per second;
            emit c(nrand3() * 2 + vec3(0, 2, 0)) at 10 per second;
            emit d(nrand3() * 2 + vec3(0, 2, 0)) at 10 per second;
            emit e(nrand3() * 2 + vec3(0, 2, 0)) at 20 per second;
            emit f(vec3(0, 2, 0), nrand3() * 3) at 30 per second;
        }
        spawn g;)";
    auto glowing = [](ViewerOptions& o) { o.glow.on = true; };
    Frame gpu = render(text, 60, Blend::Additive, {}, "glsl", {}, glowing);
    Frame jit = render(text, 60, Blend::Additive, {}, "llvm", {}, glowing);
    size_t lit = litPixels(jit), differ = differentPixels(gpu, jit);
    MESSAGE(differ << " of " << lit << " lit pixels differ by more than 2 levels");
    CHECK(lit > 3000);
    CHECK(differ <= lit / 100);
}

TEST_CASE("the glow lights the pixels around a bright sprite, and with it off they stay dark") {
    std::string text = "@shape(disc) object s { sprite(vec3(0, 2, 0), vec4(2, 1, 0.4, 1), 0.4); }\nspawn s;";
    Frame on = render(text, 1, Blend::Additive, {}, "llvm", {}, [](ViewerOptions& o) { o.glow.on = true; });
    Frame off = render(text, 1, Blend::Additive);
    Pixel nearOn = on.at(kWidth / 2 + 16, kHeight / 2), nearOff = off.at(kWidth / 2 + 16, kHeight / 2);
    CHECK(background(nearOff));
    CHECK(nearOn.r > kBackground.r + 8);
    // The core (2, 1, 0.4): without the glow red and green both clip (yellow); tone mapped,
    // green stays below red (orange).
    Pixel coreOn = on.at(kWidth / 2, kHeight / 2), coreOff = off.at(kWidth / 2, kHeight / 2);
    CHECK(coreOff.r == 255);
    CHECK(coreOff.g == 255);
    CHECK(coreOn.r >= 250);
    CHECK(coreOn.g < coreOn.r - 8);
}

TEST_CASE("alpha-blended sprites are drawn back to front, whatever their rows' order, on the host and on the GPU") {
    // The near blue sprite is created first (row 0), the far red one second: drawn in row
    // order, red would cover blue; back to front, blue is in front.
    std::string text = R"(
        @shape(disc) @blend(alpha) object s(p: vec3, c: vec4) { sprite(p, c, 2); }
        object e {
            emit s(vec3(0, 2, 2), vec4(0, 0, 1, 1));
            emit s(vec3(0, 2, -2), vec4(1, 0, 0, 1));
            kill;
        }
        spawn e;)";
    for (const char* backend : {"llvm", "interp", "glsl"}) {
        INFO(backend);
        Pixel middle = render(text, 2, Blend::Additive, {}, backend).at(kWidth / 2, kHeight / 2);
        CHECK(middle.b > 200);
        CHECK(middle.r < 40);
    }
}

TEST_CASE("many alpha-blended sprites sorted on the GPU draw what sorting on the host draws") {
    std::string text = R"(
        @shape(disc) @blend(alpha) object s(p: vec3, c: vec4) { sprite(p, c, 0.6); }
        object e { emit s(nrand3() * 3 + vec3(0, 2, 0), vec4(rand(), rand(), rand(), 0.9)) count 3000; kill; }
        spawn e;)";
    uint64_t moved = ~0ull;
    Frame gpu = render(text, 2, Blend::Additive, [&](Viewer& v) {
        // What drawing a frame more moves between the host and the GPU: no column comes back
        // to be sorted (3000 rows: 12 kB a column).
        auto& gl = dynamic_cast<gpu::GlslBackend&>(v.session().backend());
        uint64_t before = gl.transferredBytes();
        v.draw();
        moved = gl.transferredBytes() - before;
    }, "glsl");
    Frame host = render(text, 2, Blend::Additive, {}, "llvm");
    MESSAGE("bytes moved drawing a frame on the GLSL backend: " << moved);
    CHECK(moved <= 256);
    size_t lit = litPixels(host), differ = differentPixels(gpu, host);
    MESSAGE(differ << " of " << lit << " lit pixels differ by more than 2 levels");
    CHECK(lit > 10000);
    CHECK(differ <= lit / 200);
}

TEST_CASE("a textured sprite draws its flip-book's frame, tinted by its colour") {
    // A 2 × 2 flip-book of 2 × 2-pixel frames: red, green (top row), blue, white.
    const uint8_t R[4] = {255, 0, 0, 255}, G[4] = {0, 255, 0, 255}, B[4] = {0, 0, 255, 255}, W[4] = {255, 255, 255, 255};
    const uint8_t* layout[4][4] = {{R, R, G, G}, {R, R, G, G}, {B, B, W, W}, {B, B, W, W}};
    std::vector<uint8_t> image;
    for (auto& row : layout)
        for (const uint8_t* p : row) image.insert(image.end(), p, p + 4);
    std::filesystem::path file = std::filesystem::temp_directory_path() / "psys_viewer_test_atlas.png";
    REQUIRE(stbi_write_png(file.string().c_str(), 4, 4, 4, image.data(), 16));
    const Pixel expected[4] = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {255, 255, 255}};
    for (int frame = 0; frame < 6; ++frame) {
        INFO("frame " << frame);
        std::string text = fmt::format("@texture(\"{}\", 2, 2) @blend(alpha) object s {{ sprite(vec3(0, 2, 0), {}, 2, 0, {}); }}\nspawn s;",
                                       file.string(), frame == 5 ? "vec4(1, 0.5, 0.5, 1)" : "white", frame);
        Pixel middle = render(text, 1, Blend::Additive).at(kWidth / 2, kHeight / 2);
        Pixel want = expected[frame % 4];  // (frames wrap)
        if (frame == 5) want = {0, 128, 0};  // green, tinted
        CHECK(std::abs(middle.r - want.r) <= 2);
        CHECK(std::abs(middle.g - want.g) <= 2);
        CHECK(std::abs(middle.b - want.b) <= 2);
    }
}

TEST_CASE("a texture changed on disk is drawn as it is now, with no reload of the program") {
    auto write = [](const std::filesystem::path& file, Pixel p) {
        std::vector<uint8_t> image;
        for (int i = 0; i < 4; ++i) image.insert(image.end(), {uint8_t(p.r), uint8_t(p.g), uint8_t(p.b), 255});
        REQUIRE(stbi_write_png(file.string().c_str(), 2, 2, 4, image.data(), 8));
    };
    std::filesystem::path file = std::filesystem::temp_directory_path() / "psys_viewer_test_changing.png";
    write(file, {255, 0, 0});
    std::string text = fmt::format("@texture(\"{}\") @blend(alpha) object s {{ sprite(vec3(0, 2, 0), white, 2); }}\nspawn s;",
                                   file.string());
    // The run draws the red image (and keeps it); then the file turns blue and a frame
    // more is drawn.
    Frame after = render(text, 1, Blend::Additive, [&](Viewer& v) {
        write(file, {0, 0, 255});
        // A later time than the first file's, whatever the file system's clock resolution.
        std::filesystem::last_write_time(file, std::filesystem::last_write_time(file) + std::chrono::seconds(2));
        v.draw();
    });
    Pixel now = after.at(kWidth / 2, kHeight / 2);
    CHECK(now.b > 200);
    CHECK(now.r < 40);
}

TEST_CASE("with the ground shown, a sprite fades where it crosses the ground plane") {
    std::string text = "@shape(disc) @blend(alpha) object s { sprite(vec3(0, 0, 0), white, 2); }\nspawn s;";
    auto level = [](bool ground) {
        return [ground](ViewerOptions& o) {
            o.grid = ground;
            o.camera = Camera::parse("0,0,10,0,0,0");  // level with the ground: it is the middle row
        };
    };
    Frame soft = render(text, 1, Blend::Additive, {}, "llvm", {}, level(true));
    Frame hard = render(text, 1, Blend::Additive, {}, "llvm", {}, level(false));
    Camera camera = *Camera::parse("0,0,10,0,0,0");
    auto near = project(camera, {0.2f, 0.08f, 0}), far = project(camera, {0.2f, 0.8f, 0});
    REQUIRE(near);
    REQUIRE(far);
    CHECK(hard.at(near->first, near->second).r == 255);
    CHECK(soft.at(near->first, near->second).r < 40);   // 0.08 half widths above: nearly gone
    CHECK(soft.at(far->first, far->second).r > 200);    // 0.8: nearly whole (smoothstep: 0.9)
}
