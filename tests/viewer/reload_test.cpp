// Hot reload as the viewer does it: a file is saved, the watcher sees it, the reloader
// compiles it off the frame loop, and the new system takes over with the particles still
// there; a broken edit — in the file or in a file it imports —, an empty save or a deleted
// file keeps the old one running.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <thread>

#include "gpu/glsl_backend.h"
#include "reloader.h"
#include "rt/system.h"
#include "surface.h"
#include "watcher.h"

using namespace psys;
using namespace psys::viewer;
namespace fs = std::filesystem;

namespace {

struct Folder {
    fs::path path;
    Folder() : path(fs::temp_directory_path() / ("psys_reload_" + std::to_string(::getpid()))) {
        fs::create_directories(path);
    }
    ~Folder() { fs::remove_all(path); }
    // Saves as editors do: a new file renamed over the old one.
    void save(const std::string& name, const std::string& text) const {
        fs::path temporary = path / (name + ".tmp");
        std::ofstream(temporary) << text;
        fs::rename(temporary, path / name);
    }
};

// Waits until the watcher sees a save (the frame loop polls it like this).
void waitForSave(Watcher& watcher) {
    for (int i = 0; i < 500; ++i) {
        if (watcher.changed()) return;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    FAIL("the watcher did not see the save");
}

// Frames go on until the reloader says what became of the save (the JIT's system, or
// the errors).
Reloader::Outcome waitForReload(Reloader& reloader, host::Session& session, int& frame) {
    for (int i = 0; i < 1000; ++i) {
        REQUIRE_FALSE(session.frame(++frame, 1.0 / 60));
        if (auto outcome = reloader.poll(); outcome && outcome->kind != Reloader::Outcome::Kind::Interim) return *outcome;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    FAIL("the reload did not finish");
    return {};
}

const char* kLib = "fn lift() -> vec3 = vec3(0, 1, 0);\n";
const char* kMain = "import \"lib.psys\";\n"
                    "object p { pos = integrate(lift()); point(pos, white, 1); }\n"
                    "object e { emit p at 60 per second; }\nspawn e;\n";

// Saves kMain drawing red points of size 3 and waits for the reload: adopted, the `live`
// particles and their emitter carried over, drawn as the edit says.
Reloader::Outcome saveRedAndReload(const Folder& folder, Watcher& watcher, Reloader& reloader, host::Session& session,
                                   int& frame, size_t live) {
    std::string edited = kMain;
    edited.replace(edited.find("point(pos, white, 1)"), 20, "point(pos, red, 3)");
    folder.save("main.psys", edited);
    waitForSave(watcher);
    reloader.saved(Clock::now());
    Reloader::Outcome outcome = waitForReload(reloader, session, frame);
    REQUIRE(outcome.kind == Reloader::Outcome::Kind::Adopted);
    CHECK(outcome.report->carried >= live + 1);
    auto points = session.system().points(0);
    REQUIRE(points.size() >= live);
    CHECK(points[0].size == 3);
    CHECK(points[0].color[1] == 0);
    CHECK(points[0].position[1] > 0.5f);  // the integral carried on from before the reload
    return outcome;
}

}  // namespace

TEST_CASE("a save is seen, compiled off the frame loop, and the particles stay") {
    Folder folder;
    folder.save("lib.psys", kLib);
    folder.save("main.psys", kMain);
    host::SessionOptions options;
    host::CompileResult compiled;
    std::string error;
    auto session = host::Session::open((folder.path / "main.psys").string(), options, compiled, error);
    REQUIRE_MESSAGE(session != nullptr, compiled.text(), error);
    Watcher watcher;
    REQUIRE(watcher.ok());
    std::vector<std::string> files;
    for (int f = 0; f < compiled.sources->count(); ++f) files.push_back(compiled.sources->file(f).path());
    watcher.watch(files);
    Reloader reloader(*session);
    int frame = 0;
    for (; frame < 60;) REQUIRE_FALSE(session->frame(++frame, 1.0 / 60));
    size_t live = session->system().stats().types[0].live;
    REQUIRE(live > 50);

    SUBCASE("an edit of the file") { saveRedAndReload(folder, watcher, reloader, *session, frame, live); }
    SUBCASE("a broken edit keeps the old system running, until the next good save") {
        folder.save("main.psys", std::string(kMain) + "broken\n");
        waitForSave(watcher);
        reloader.saved(Clock::now());
        Reloader::Outcome outcome = waitForReload(reloader, *session, frame);
        CHECK(outcome.kind == Reloader::Outcome::Kind::Failed);
        CHECK(outcome.compile.text().find("main.psys:5:1: error:") != std::string::npos);
        CHECK(session->system().stats().types[0].live >= live);
        REQUIRE_FALSE(session->frame(++frame, 1.0 / 60));
        folder.save("main.psys", kMain);
        waitForSave(watcher);
        reloader.saved(Clock::now());
        CHECK(waitForReload(reloader, *session, frame).kind == Reloader::Outcome::Kind::Adopted);
    }
    SUBCASE("an empty save (an editor that truncates, then writes) keeps the system running") {
        folder.save("main.psys", "  \n\n");
        waitForSave(watcher);
        reloader.saved(Clock::now());
        CHECK(waitForReload(reloader, *session, frame).kind == Reloader::Outcome::Kind::Empty);
        CHECK(session->system().stats().types[0].live >= live);  // nothing adopted: the particles stay
        folder.save("main.psys", kMain);
        waitForSave(watcher);
        reloader.saved(Clock::now());
        CHECK(waitForReload(reloader, *session, frame).kind == Reloader::Outcome::Kind::Adopted);
    }
    SUBCASE("a deleted file keeps the system running, and is picked up when it returns") {
        fs::remove(folder.path / "main.psys");
        waitForSave(watcher);  // (a deletion is seen as a change)
        reloader.saved(Clock::now());
        CHECK(waitForReload(reloader, *session, frame).kind == Reloader::Outcome::Kind::Vanished);
        CHECK(session->system().stats().types[0].live >= live);
        saveRedAndReload(folder, watcher, reloader, *session, frame, live);
    }
    SUBCASE("an edit that breaks an import keeps the old system running") {
        folder.save("lib.psys", "fn lift() -> vec3 = vec3(0, 1);\n");
        waitForSave(watcher);
        reloader.saved(Clock::now());
        Reloader::Outcome outcome = waitForReload(reloader, *session, frame);
        CHECK(outcome.kind == Reloader::Outcome::Kind::Failed);
        CHECK(outcome.compile.text().find("lib.psys:1:") != std::string::npos);
        CHECK(session->system().stats().types[0].live >= live);
        folder.save("lib.psys", "fn lift() -> vec3 = vec3(0, 2, 0);\n");
        waitForSave(watcher);
        reloader.saved(Clock::now());
        CHECK(waitForReload(reloader, *session, frame).kind == Reloader::Outcome::Kind::Adopted);
    }
}

TEST_CASE("a save reloads a system on the GPU: its shaders compile on the frame loop's thread, not the reloader's") {
    // The reloader prepares the new module off the frame loop; the GLSL backend's GL
    // context is the frame loop's, so it compiles when the new system is made there
    // (before, the reloader's thread made GL calls without a context: the viewer aborted).
    Folder folder;
    folder.save("lib.psys", kLib);
    folder.save("main.psys", kMain);
    host::SessionOptions options;
    options.backend = {"glsl", "fast"};
    host::CompileResult compiled;
    std::string error;
    auto session = host::Session::open((folder.path / "main.psys").string(), options, compiled, error);
    REQUIRE_MESSAGE(session != nullptr, compiled.text(), error);
    REQUIRE(session->backend().name() == "glsl");
    Watcher watcher;
    REQUIRE(watcher.ok());
    watcher.watch({(folder.path / "main.psys").string()});
    Reloader reloader(*session);
    int frame = 0;
    for (; frame < 60;) REQUIRE_FALSE(session->frame(++frame, 1.0 / 60));
    size_t live = session->system().stats().types[0].live;
    REQUIRE(live > 50);
    saveRedAndReload(folder, watcher, reloader, *session, frame, live);
}

TEST_CASE("a reload that waits too long for the JIT runs on the interpreter meanwhile, then moves to the JIT") {
    Folder folder;
    folder.save("lib.psys", kLib);
    folder.save("main.psys", kMain);
    host::SessionOptions options;
    host::CompileResult compiled;
    std::string error;
    auto session = host::Session::open((folder.path / "main.psys").string(), options, compiled, error);
    REQUIRE(session);
    Reloader reloader(*session);
    reloader.interimAfterSeconds = 0;  // no waiting at all
    int frame = 0;
    for (; frame < 30;) REQUIRE_FALSE(session->frame(++frame, 1.0 / 60));
    std::string edited = kMain;
    edited.replace(edited.find("white"), 5, "green");
    folder.save("main.psys", edited);
    reloader.saved(Clock::now());
    bool interim = false;
    for (int i = 0; i < 2000; ++i) {
        REQUIRE_FALSE(session->frame(++frame, 1.0 / 60));
        auto outcome = reloader.poll();
        if (outcome && outcome->kind == Reloader::Outcome::Kind::Interim) {
            interim = true;
            CHECK(session->backend().name() == "interp");
            CHECK(session->system().points(0).at(0).color[1] == 1);  // green, on the interpreter
        }
        if (outcome && outcome->kind == Reloader::Outcome::Kind::Adopted) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    CHECK(session->backend().name() == "llvm");
    CHECK(session->system().points(0).at(0).color[1] == 1);
    (void)interim;  // the JIT may win the race on a fast machine: both orders are right
}

namespace {

// A reload on the GLSL backend drawing into an offscreen surface's context: with the
// surface's worker context, its programs are compiled on the reloader's thread; without,
// a slice a frame (Backend::prepareSome). Either way the new system draws as the edit says.
void glslReload(bool workerContext) {
    std::string error;
    auto surface = openOffscreen(64, 64, error);
    REQUIRE_MESSAGE(surface, error);
    std::unique_ptr<WorkerContext> worker = workerContext ? surface->workerContext() : nullptr;
    if (workerContext) REQUIRE(worker);
    Folder folder;
    folder.save("lib.psys", kLib);
    folder.save("main.psys", kMain);
    host::SessionOptions options;
    options.backend.name = "glsl";
    host::CompileResult compiled;
    auto session = host::Session::open((folder.path / "main.psys").string(), options, compiled, error);
    REQUIRE_MESSAGE(session, compiled.text(), error);
    auto* glsl = dynamic_cast<gpu::GlslBackend*>(&session->backend());
    REQUIRE(glsl);
    Watcher watcher;
    watcher.watch({(folder.path / "main.psys").string(), (folder.path / "lib.psys").string()});
    Reloader reloader(*session, worker.get());
    reloader.sliceSeconds = 0;  // a program a frame
    int frame = 0;
    for (; frame < 60;) REQUIRE_FALSE(session->frame(++frame, 1.0 / 60));
    size_t live = session->system().stats().types[0].live;
    size_t programs = rt::launchPlan(session->system().module()).rows.size() +
                      rt::launchPlan(session->system().module()).children.size();
    Reloader::Outcome outcome = saveRedAndReload(folder, watcher, reloader, *session, frame, live);
    CHECK(glsl->sharedPrograms() == (workerContext ? programs : 0));
    // Without a worker context, every program compiled in a frame of its own.
    CHECK(outcome.frameSlices == (workerContext ? 0 : static_cast<int>(programs)));
}

}  // namespace

TEST_CASE("a GLSL reload compiles its programs on the reloader's thread, in a context sharing the viewer's") {
    glslReload(true);
}

TEST_CASE("a GLSL reload without a worker context compiles a program a frame before the new system takes over") {
    glslReload(false);
}

TEST_CASE("prepareSome with no time to spare: one program a call, true with the last") {
    std::string error;
    auto surface = openOffscreen(64, 64, error);
    REQUIRE_MESSAGE(surface, error);
    host::SessionOptions options;
    options.backend.name = "glsl";
    host::CompileResult compiled;
    std::string text = std::string(kMain).substr(std::string(kMain).find('\n') + 1);
    text.replace(text.find("lift()"), 6, "vec3(0, 1, 0)");
    auto session = host::Session::open("slices.psys", options, compiled, error, &text);
    REQUIRE_MESSAGE(session, compiled.text(), error);
    // Another module of the same program: new kernels, none compiled yet.
    std::optional<ir::Module> module;
    REQUIRE(host::compile("slices.psys", options.compile, module, &text).ok);
    rt::Plan plan = rt::launchPlan(*module);
    size_t programs = plan.rows.size() + plan.children.size(), calls = 1;
    REQUIRE(programs >= 3);
    size_t before = session->backend().report().kernels;
    while (!session->backend().prepareSome(plan, 0)) {
        ++calls;
        CHECK(session->backend().report().kernels == before + calls - 1);
    }
    CHECK(calls == programs);
    CHECK(session->backend().report().kernels == before + programs);
    CHECK(session->backend().prepareSome(plan, 0));  // nothing left: nothing compiled
    CHECK(session->backend().report().kernels == before + programs);
    session->backend().forget(*module);
}
