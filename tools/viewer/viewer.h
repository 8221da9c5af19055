// psys-view: a system in real time, edited live (docs/viewer.md).
//
// The Viewer runs a host::Session frame by frame on a Surface (a window, or offscreen
// when headless): it steps the system (fixed 1/60 s or real time, scaled, paused, one step
// at a time), draws every type's points from the run-time's draw columns, shows the panel
// (externs, triggers, time, backend) and the stats, watches the file and everything it
// imports and hot-reloads on save (tools/viewer/reloader.h), and writes screenshots.
#pragma once

#include <chrono>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "camera.h"
#include "host/session.h"
#include "reloader.h"
#include "render.h"
#include "script.h"
#include "surface.h"
#include "watcher.h"

namespace psys::viewer {

class Panel;

struct ViewerOptions {
    std::string file;
    // The errors of a file that did not compile at the start: the window opens on an empty
    // system showing them, and the first good save takes over.
    std::string startErrors;
    bool headless = false;
    int frames = 0;              // 0: until the window is closed (headless: 1)
    std::string screenshot;      // a PNG of the last frame
    std::string record;          // a folder: a PNG every `every` frames
    int every = 1;
    std::optional<Camera> camera;
    std::vector<host::ExternSetting> sets;
    std::vector<host::TriggerFiring> fires;
    host::SessionOptions session;
    double dt = 1.0 / 60;
    bool realTime = false;
    int width = 1280, height = 720;
    Blend blend = Blend::Additive;
    bool ui = true;
    bool grid = true;
    bool fit = false;            // the camera fits what is alive before each frame is drawn
    bool watch = true;
    Script script;
    bool log = false;            // say on stdout what happens (reloads, their latency)
    double fps = 0;              // at most this many frames a second (0: as many as it can)
    double interimAfter = 0.05;
    int warmup = 0;              // frames left out of the summary --log prints  // seconds a reload waits for the JIT before running on the interpreter
};

class Viewer {
public:
    Viewer(ViewerOptions options, Surface& surface, std::unique_ptr<host::Session> session,
           host::CompileResult compiled);
    ~Viewer();
    // The frame loop; the process's exit status.
    int run();

    // Input, from the window or from a script.
    void key(int key, bool shift);
    void orbit(float dx, float dy) { camera_.orbit(dx, dy); }
    void pan(float dx, float dy) { camera_.pan(dx, dy, static_cast<float>(surface_.height())); }
    void zoom(float steps) { camera_.zoom(steps); }
    void frameAlive();
    std::optional<std::string> set(const host::ExternSetting& setting);
    std::optional<std::string> fire(const std::string& trigger, const std::vector<float>& args);
    bool screenshot(const std::string& path);

    host::Session& session() { return *session_; }
    const Camera& camera() const { return camera_; }

private:
    friend class Panel;  // the panel shows and sets what the viewer runs
    struct FrameStats {
        double frameSeconds = 0, stepSeconds = 0, glSeconds = 0;
        rt::Stats before, after;  // the run-time's stats around the frame's steps
    };

    void frame();
    void step(double seconds);
    void handleReload();
    void draw();
    void restart(uint32_t seed);
    void watchSources(const host::CompileResult& compiled);
    void say(const std::string& line) const;
    void runScript();

    ViewerOptions options_;
    Surface& surface_;
    std::unique_ptr<host::Session> session_;
    Camera camera_;
    std::unique_ptr<PointRenderer> points_;
    std::unique_ptr<SceneRenderer> scene_;
    Watcher watcher_;
    std::unique_ptr<Reloader> reloader_;
    std::unique_ptr<Panel> panel_;

    int frame_ = 0;                 // frames drawn (from 1)
    bool paused_ = false, stepOnce_ = false, quit_ = false;
    double timeScale_ = 1;
    bool fixedDt_ = true;
    Clock::time_point lastFrame_;
    FrameStats stats_;
    double fps_ = 0;
    double lastCompileSeconds_ = 0;
    std::optional<double> lastReloadSeconds_;
    std::optional<Clock::time_point> reloadSaved_;  // the save behind the system adopted this frame
    bool interim_ = false;                          // a reloaded system runs on the interpreter meanwhile
    std::string reloadNote_;        // what the last reload did
    std::vector<std::string> shots_;  // a script's screenshots of this frame, written once it is drawn
    std::string diagnostics_;       // the last failed compile's errors, until a good one
    int status_ = 0;
    // Sums over the frames drawn, for the summary --log prints at the end.
    struct Totals {
        int frames = 0;
        double frame = 0, step = 0, draw = 0;
    } totals_;
};

}  // namespace psys::viewer
