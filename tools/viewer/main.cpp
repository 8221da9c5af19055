// psys-view: see a system, edit it, and watch it change on save (docs/viewer.md).
//
//   psys-view FILE                         a window (Xvfb or a desktop), the JIT, hot reload
//   psys-view --headless FILE --frames N --screenshot out.png
//                                          no display: EGL surfaceless, images
//
// Exit status: 0, 1 (the file does not compile — headless or not watching; a window
// waits for a fix —, a frame failed, or an image could not be written), 2 (bad usage or
// no way to draw).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include <CLI/CLI.hpp>

#include "host/large_stack.h"
#include "image_file.h"
#include "keys.h"
#include "viewer.h"

using namespace psys;
using namespace psys::viewer;

namespace {

std::string footer() {
    return "\nMouse and keys (F1 or ? shows them over the frame):\n" + keysText() +
           "Hot reload: saving FILE (or a file it imports) compiles it in the background; the new\n"
           "system takes over with the particles still flying. An edit that does not compile, an\n"
           "empty save or a vanished file leave the old one running and show why.";
}

int fail(const std::string& message) {
    std::cerr << "psys-view: error: " << message << "\n";
    return 2;
}

// A file or folder the run would write that cannot be: said before anything runs, exit 1.
int cannotWrite(const std::string& path, const std::string& reason) {
    std::cerr << "psys-view: error: cannot write `" << path << "`: " << reason << "\n";
    return 1;
}

}  // namespace

namespace {

// CLI11's ranges let NaN through (it compares false with both bounds).
const CLI::Validator kFinite(
    [](std::string& text) {
        char* end = nullptr;
        double v = std::strtod(text.c_str(), &end);
        return *end == '\0' && std::isfinite(v) ? std::string() : "`" + text + "` is not a finite number";
    },
    "FINITE");

int realMain(int argc, char** argv) {
    CLI::App app{"psys-view: run a .psys system in real time, edit it live"};
    app.footer(footer());
    ViewerOptions o;
    std::vector<std::string> sets, fires;
    std::string camera, dt = "1/60", script, size = "1280x720", blend = "additive";
    bool noUi = false, ui = false, noWatch = false, noGrid = false;
    bool keys = false, realTime = false, fixed = false;
    app.add_option("file", o.file, "The system to view")->type_name("FILE");
    app.add_flag("--keys", keys, "Print the mouse and keys as a Markdown table (docs/viewer.md) and exit");
    app.add_flag("--headless", o.headless, "No window: render offscreen (EGL surfaceless) and write PNGs");
    app.add_option("--frames", o.frames, "Frames to run, then exit (0: until the window closes; headless: 1)")
        ->check(CLI::Range(0, 1000000000));
    app.add_option("--screenshot", o.screenshot, "Write the last frame to this image (.png, .jpg, .bmp or .tga)");
    app.add_option("--record", o.record,
                   "Record every --every frame: into a folder as PNGs, or an .mp4 or .gif (ffmpeg on the PATH); "
                   "at --dt a frame, it plays at the simulation's speed");
    app.add_option("--every", o.every, "With --record: every Nth frame (1)")->check(CLI::Range(1, 1000000000));
    app.add_option("--camera", camera, "yaw,pitch,distance[,x,y,z]: degrees and units, looking at (x, y, z)");
    app.add_option("--set", sets, "Set an extern: NAME=VALUE or NAME=X,Y,Z (repeatable)")->allow_extra_args(false);
    app.add_option("--fire", fires, "Fire a trigger before a frame: TRIGGER[:X,Y,Z]@FRAME (repeatable)")->allow_extra_args(false);
    app.add_option("--backend", o.session.backend.name, "llvm (the default), interp or glsl (compute shaders on the GL the viewer draws with)")
        ->check(CLI::IsMember(host::backendNames()));
    app.add_option("--math", o.session.backend.math, "llvm: fast (the default) or exact")->check(CLI::IsMember({"fast", "exact"}));
    std::string integrator;
    std::vector<std::string> methods(core::kIntegratorNames.begin(), core::kIntegratorNames.end());
    app.add_option("--integrator", integrator,
                   "Integrate every object with this method, whatever its @integrator says (docs/accuracy.md)")
        ->check(CLI::IsMember(methods))->type_name("METHOD");
    app.add_option("--seed", o.session.system.seed, "Random seed (1)");
    app.add_option("--threads", o.session.system.threads, "Threads for the simulation: 0 for every core (0)")
        ->check(CLI::Range(0u, rt::SystemOptions::kMostThreads));
    app.add_option("--dt", dt, "Seconds a step simulates (1/60)");
    auto* realFlag = app.add_flag("--real-time", realTime,
                                  "Headless: run steps of --dt as wall-clock time passes (a window's default)");
    app.add_flag("--fixed", fixed, "A step of --dt a frame, however long the frame took (headless's default; T switches)")
        ->excludes(realFlag);
    app.add_option("--max-steps", o.maxSteps, "In real time, the most steps a frame runs after a stall (8)")
        ->check(CLI::Range(1, 1000));
    app.add_option("--size", size, "Width x height of the window or image (1280x720)");
    app.add_option("--blend", blend, "How types whose program names no @blend are blended: additive (the default) or alpha (B switches)")
        ->check(CLI::IsMember({"additive", "alpha"}));
    bool noGlow = false;
    app.add_flag("--no-glow", noGlow, "No glow and no tone mapping: light clipped at 1 (L switches)");
    app.add_option("--glow", o.glow.strength, "How much the glow adds (0.6)")->check(CLI::Range(0.0, 10.0));
    app.add_flag("--fit", o.fit, "The camera fits what is alive before each frame (as F does)");
    app.add_flag("--no-grid", noGrid, "No ground grid and axes (G switches)");
    app.add_flag("--no-ui", noUi, "No panel");
    app.add_flag("--ui", ui, "The panel in --headless images too");
    app.add_flag("--no-watch", noWatch, "Do not reload the file when it is saved");
    app.add_option("--script", script, "Scripted input, an action a line (docs/viewer.md)")->type_name("FILE");
    app.add_option("--fps", o.fps, "At most this many frames a second (0: as many as it can)")
        ->check(kFinite & CLI::Range(0.0, 10000.0));
    app.add_option("--interim-after", o.interimAfter,
                   "Seconds a reload waits for the JIT before the new system runs on the interpreter meanwhile (0.05)")
        ->check(kFinite & CLI::Range(0.0, 3600.0));
    app.add_option("--warmup", o.warmup, "Frames left out of the timing summary --log prints (0)")->check(CLI::Range(0, 1000000000));
    app.add_flag("--log", o.log, "Say on stdout what happens: reloads and their latency, images written");
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        int code = app.exit(e);
        return e.get_exit_code() == 0 ? 0 : (code == 0 ? 0 : 2);
    }

    if (keys) {
        std::cout << keysMarkdown();
        return 0;
    }
    if (o.file.empty()) return fail("a FILE to view is needed (psys-view --help)");
    o.fixed = o.headless ? !realTime : fixed;
    if (!integrator.empty()) o.session.compile.pipeline.pass.everyObject = core::integratorFromName(integrator);
    for (const std::string& s : sets) {
        auto setting = host::parseSet(s);
        if (!setting) return fail(setting.error);
        o.sets.push_back(*setting);
    }
    for (const std::string& f : fires) {
        auto firing = host::parseFire(f);
        if (!firing) return fail(firing.error);
        o.fires.push_back(*firing);
    }
    auto step = host::parseStep(dt);
    if (!step || *step <= 0) return fail("--dt takes a positive number of seconds, not `" + dt + "`");
    o.dt = *step;
    if (!camera.empty()) {
        o.camera = Camera::parse(camera);
        if (!o.camera) return fail("--camera takes yaw,pitch,distance or yaw,pitch,distance,x,y,z, not `" + camera + "`");
    }
    char extra = 0;
    if (std::sscanf(size.c_str(), "%dx%d%c", &o.width, &o.height, &extra) != 2 || o.width < 16 || o.height < 16 ||
        o.width > 16384 || o.height > 16384)
        return fail("--size takes WIDTHxHEIGHT, such as 1280x720, not `" + size + "`");
    if (!o.screenshot.empty())
        if (auto problem = imageFormatProblem(o.screenshot))
            return cannotWrite(o.screenshot, *problem);
    if (!o.record.empty())
        if (auto problem = Recorder::problem(o.record)) return cannotWrite(o.record, *problem);
    if (!script.empty()) {
        std::error_code folder;
        if (std::filesystem::is_directory(script, folder)) return fail("cannot read `" + script + "`: it is a folder");
        std::ifstream in(script);
        if (!in) return fail("cannot read `" + script + "`");
        std::stringstream text;
        text << in.rdbuf();
        std::string error;
        auto parsed = Script::parse(text.str(), script, error);
        if (!parsed) return fail(error);
        o.script = *parsed;
    }
    o.blend = blend == "alpha" ? Blend::Alpha : Blend::Additive;
    o.grid = !noGrid;
    o.glow.on = !noGlow;
    o.ui = o.headless ? ui : !noUi;
    o.watch = !noWatch;

    std::string error;
    std::unique_ptr<Surface> surface = o.headless ? openOffscreen(o.width, o.height, error)
                                                  : openWindow(o.width, o.height, "psys-view: " + o.file, error);
    if (!surface) return fail(error);
    host::CompileResult compiled;
    auto session = host::Session::open(o.file, o.session, compiled, error);
    if (compiled.diagnostics) compiled.diagnostics->setProgram("psys-view");
    compiled.print(std::cerr, false);
    if (!compiled.ok) {
        // Headless, or not watching, there is nothing to wait for. A window opens on an empty
        // system with the errors shown, and the first save that compiles takes over.
        if (o.headless || !o.watch) return 1;
        o.startErrors = compiled.text();
        static const std::string nothing;
        host::CompileResult empty;
        session = host::Session::open(o.file, o.session, empty, error, &nothing);
        o.sets.clear();  // (for a program not there yet)
        o.fires.clear();
    }
    if (!session) return fail(error);
    for (const host::ExternSetting& s : o.sets)
        if (auto e = session->apply(s)) return fail("--set " + s.name + ": " + *e);
    int lastFrame = o.headless ? std::max(o.frames, 1) : o.frames;
    if (auto e = session->schedule(o.fires, lastFrame)) return fail(*e);
    if (o.log) std::cout << "psys-view: " << o.file << " on " << session->backend().name() << ", " << surface->renderer() << std::endl;
    Viewer viewer(std::move(o), *surface, std::move(session), compiled);
    try {
        return viewer.run();
    } catch (const std::exception& e) {  // a backend that cannot go on (a GPU out of memory, …): a frame failed
        std::cerr << "psys-view: error: " << e.what() << "\n";
        return 1;
    }
}

}  // namespace

// Everything runs on a thread with a large stack (host/large_stack.h).
int main(int argc, char** argv) {
    return psys::host::runWithLargeStack([&] { return realMain(argc, argv); });
}
