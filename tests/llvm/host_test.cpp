// The host library: settings as people write them, backends by name, sessions that run a
// file, reload it on request (a broken edit keeps the old system running) and move to
// another backend without losing an object.
#include <doctest/doctest.h>

#include <array>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "host/session.h"
#include "tests/system_support.h"

using namespace psys;

namespace {

struct TempFile {
    std::filesystem::path path;
    explicit TempFile(const std::string& name) : path(std::filesystem::temp_directory_path() / name) {}
    ~TempFile() { std::filesystem::remove(path); }
    void write(const std::string& text) const { std::ofstream(path) << text; }
};

}  // namespace

TEST_CASE("host settings: numbers, extern settings and trigger firings, and what is wrong with bad ones") {
    CHECK(*host::parseNumber("1/60") == doctest::Approx(1.0 / 60));
    CHECK(*host::parseNumber("1e-3") == 1e-3);
    CHECK(*host::parseNumber("1/60/2") == doctest::Approx(1.0 / 120));  // left to right, as written (was 1/30)
    CHECK_FALSE(host::parseStep("1/60/0"));                              // infinite, not 0 (1/(60/0))
    CHECK_FALSE(host::parseNumber("fast"));
    CHECK_FALSE(host::parseNumber(""));
    auto set = host::parseSet("wind=1,2,3");
    REQUIRE(set);
    CHECK(set->name == "wind");
    CHECK(set->values == std::vector<float>{1, 2, 3});
    CHECK(host::parseSet("wind").error == "--set takes NAME=VALUE or NAME=X,Y,Z, not `wind`");
    CHECK_FALSE(host::parseSet("=3"));
    CHECK_FALSE(host::parseSet("w=1,,2"));
    auto fire = host::parseFire("explosion:0,5,0@12");
    REQUIRE(fire);
    CHECK(fire->trigger == "explosion");
    CHECK(fire->args == std::vector<float>{0, 5, 0});
    CHECK(fire->frame == 12);
    CHECK(host::parseFire("go@3")->args.empty());
    CHECK(host::parseFire("go").error ==
          "--fire takes TRIGGER@FRAME or TRIGGER:X,Y,Z@FRAME with FRAME a whole number from 1, not `go`");
    CHECK_FALSE(host::parseFire("go@0"));
    CHECK_FALSE(host::parseFire("go@1.5"));
    CHECK_FALSE(host::parseFire("go@1e20"));
    CHECK(host::parseSet("lit=true")->values == std::vector<float>{1});
    CHECK(host::parseSet("lit=false")->values == std::vector<float>{0});
    CHECK_FALSE(host::parseFire("go@-1"));
    CHECK(host::parseStep("x").error.find("--dt takes a number of seconds") == 0);
}

TEST_CASE("backends by name") {
    CHECK(host::backendNames().front() == "llvm");
    for (const std::string& name : host::backendNames()) {
        auto backend = host::makeBackend({name, "fast"});
        REQUIRE(backend);
        CHECK((*backend)->name() == name);
    }
    CHECK(host::makeBackend({"vulkan", "fast"}).error == "there is no backend `vulkan`; the backends are llvm, interp, glsl");
    CHECK(host::makeBackend({"llvm", "sloppy"}).error == "the maths is fast or exact, not `sloppy`");
}

TEST_CASE("a session runs a file, and a broken edit keeps the old system running") {
    TempFile file("psys_host_reload.psys");
    file.write("object p { pos = integrate(vec3(1, 0, 0)); point(pos, white, 1); }\nspawn p;\n");
    host::SessionOptions options;
    host::CompileResult compiled;
    std::string error;
    auto session = host::Session::open(file.path.string(), options, compiled, error);
    REQUIRE_MESSAGE(session != nullptr, compiled.text(), error);
    for (int frame = 1; frame <= 60; ++frame) REQUIRE_FALSE(session->frame(frame, 1.0 / 60));

    file.write("object p { pos = integrate(vec3(1, 0, 0)) + nope; point(pos, white, 1); }\nspawn p;\n");
    auto broken = session->reload();
    CHECK_FALSE(broken.compile.ok);
    CHECK_FALSE(broken.report);
    CHECK(broken.compile.text().find("error: unknown name `nope`") != std::string::npos);
    REQUIRE_FALSE(session->frame(61, 1.0 / 60));  // still running the old system
    CHECK(session->system().points(0).at(0).position[0] == doctest::Approx(61.0 / 60).epsilon(1e-4));

    file.write("object p { pos = integrate(vec3(1, 0, 0)); point(pos + vec3(0, 5, 0), white, 2); }\nspawn p;\n");
    auto good = session->reload();
    REQUIRE(good.compile.ok);
    REQUIRE(good.report);
    CHECK(good.report->carried == 1);
    REQUIRE_FALSE(session->frame(62, 1.0 / 60));
    auto p = session->system().points(0).at(0);
    CHECK(p.position[0] == doctest::Approx(62.0 / 60).epsilon(1e-4));  // the integral went on
    CHECK(p.position[1] == 5);                                         // the new equation
    CHECK(p.size == 2);
}

namespace {

std::string sampleText(const std::string& name) {
    std::ifstream in(std::string(PSYS_SAMPLES_DIR) + "/" + name + ".psys");
    return {std::istreambuf_iterator<char>(in), {}};
}

// Two sessions of one text: one to move between backends, one to stay on `backend`.
std::pair<std::unique_ptr<host::Session>, std::unique_ptr<host::Session>> twoSessions(const std::string& text,
                                                                                      host::BackendChoice moving,
                                                                                      host::BackendChoice backend) {
    host::SessionOptions a, b;
    a.backend = moving;
    b.backend = backend;
    host::CompileResult compiled;
    std::string error;
    auto first = host::Session::open("sample.psys", a, compiled, error, &text);
    auto second = host::Session::open("sample.psys", b, compiled, error, &text);
    REQUIRE(first);
    REQUIRE(second);
    return {std::move(first), std::move(second)};
}

}  // namespace

TEST_CASE("a session moves to another backend without losing a step: llvm (exact) to the interpreter") {
    std::string text = sampleText("fireworks");
    auto [moving, straight] = twoSessions(text, {"llvm", "exact"}, {"interp", "fast"});
    CHECK(test::drawnBytes(moving->system(), 120) == test::drawnBytes(straight->system(), 120));
    REQUIRE_FALSE(moving->switchBackend({"interp", "fast"}));
    CHECK(moving->backend().name() == "interp");
    CHECK(test::drawnBytes(moving->system(), 120) == test::drawnBytes(straight->system(), 120));
    CHECK(moving->switchBackend({"nope", "fast"}).value().find("there is no backend") == 0);
}

TEST_CASE("a session moves onto the GPU backend and back without losing a step") {
    // The fireworks compute only + − × ÷ and draws: bit for bit on the GPU (docs/gpu.md).
    std::string text = sampleText("fireworks");
    auto [moving, straight] = twoSessions(text, {"interp", "fast"}, {"interp", "fast"});
    CHECK(test::drawnBytes(moving->system(), 60) == test::drawnBytes(straight->system(), 60));
    REQUIRE_FALSE(moving->switchBackend({"glsl", "fast"}));
    CHECK(moving->backend().name() == "glsl");
    CHECK(test::drawnBytes(moving->system(), 120) == test::drawnBytes(straight->system(), 120));
    REQUIRE_FALSE(moving->switchBackend({"interp", "fast"}));
    CHECK(test::drawnBytes(moving->system(), 60) == test::drawnBytes(straight->system(), 60));
}

TEST_CASE("fast maths compiles with the relaxed rewrites, exact maths and the interpreter without — a session keeps its choice") {
    std::string text = sampleText("fire");
    auto slots = [](const host::Session& s) {
        std::string names;
        for (const ir::StateSlot& slot : s.system().module().objects[0].state) names += slot.name + " ";
        return names;
    };
    host::CompileResult compiled;
    std::string error;
    for (auto [name, math, relaxed] : {std::tuple{"llvm", "fast", true}, {"llvm", "exact", false}, {"interp", "fast", false}}) {
        INFO(name << " " << math);
        host::SessionOptions options;
        options.backend = {name, math};
        options.reloadable = false;  // as psysc run: the closed forms (the reload tests are below)
        auto session = host::Session::open("fire.psys", options, compiled, error, &text);
        REQUIRE(session);
        // The fire's pos = snapshot(ipos) + integrate(vel): one integral starting at ipos.
        CHECK((slots(*session).find("integrate@pos.from-creation") != std::string::npos) == relaxed);
        CHECK(session->options().compile.pipeline.pass.relaxed == relaxed);
        if (relaxed) {  // the interpreter runs the same (relaxed) program after a switch
            REQUIRE_FALSE(session->switchBackend({"interp", "fast"}));
            CHECK(slots(*session).find("integrate@pos.from-creation") != std::string::npos);
            CHECK(session->reload(&text).compile.ok);
            CHECK(slots(*session).find("integrate@pos.from-creation") != std::string::npos);
        }
    }
}

namespace {

// A session of `text` on the JIT in `math`, run `frames` frames, reloaded with `edit`, run
// one more: the first object's position.
std::array<float, 3> reloadedPosition(const std::string& text, const std::string& edit, const char* math, int frames) {
    host::SessionOptions options;
    options.backend = {"llvm", math};
    host::CompileResult compiled;
    std::string error;
    auto session = host::Session::open("edit.psys", options, compiled, error, &text);
    REQUIRE_MESSAGE(session, compiled.text(), error);
    for (int f = 1; f <= frames; ++f) REQUIRE_FALSE(session->frame(f, 1.0 / 60));
    auto reloaded = session->reload(&edit);
    REQUIRE_MESSAGE(reloaded.compile.ok, reloaded.compile.text());
    REQUIRE_FALSE(session->frame(frames + 1, 1.0 / 60));
    auto points = session->system().points(0);
    REQUIRE_FALSE(points.empty());
    return points[0].position;
}

}  // namespace

TEST_CASE("a session that may reload carries the same state under fast maths as under exact maths") {
    // Under fast maths a run's integral of what is fixed at creation is c·age, and
    // `ip + integrate(vel)` one integral that starts at ip (ip then not kept): a reload
    // found neither, and put objects at the origin or dropped their velocity. A session
    // compiles what a reload can carry (opt::PassOptions::reloadable) in either maths.
    const std::string projectile =
        "object p(ip: vec3, v0: vec3, k: float) { vel = v0 + integrate(vec3(0, -9.8, 0));\n"
        "  pos = ip + integrate(vel); point(pos, white, 1); }\n"
        "object e { emit p(vec3(0, 5 + rand(), 0), vec3(rand(), 3, 0), 0.5) count 3; }\nspawn e;";
    struct Edit {
        const char* what;
        std::string from, to;
    };
    for (const Edit& e : {Edit{"a position that no longer integrates", "pos = ip + integrate(vel)", "pos = ip"},
                          Edit{"a drag term added", "integrate(vec3(0, -9.8, 0))", "integrate(vec3(0, -9.8, 0) - k * vel)"},
                          Edit{"gravity changed", "vec3(0, -9.8, 0)", "vec3(0, -4, 0)"},
                          Edit{"a start added to an integral", "pos = ip + integrate(vel)", "pos = ip * 2 + integrate(vel)"}}) {
        INFO(e.what);
        std::string edit = projectile;
        edit.replace(edit.find(e.from), e.from.size(), e.to);
        auto fast = reloadedPosition(projectile, edit, "fast", 30);
        auto exact = reloadedPosition(projectile, edit, "exact", 30);
        for (int c = 0; c < 3; ++c) CHECK(fast[c] == doctest::Approx(exact[c]).epsilon(1e-5));
    }
}
