// psys-view: a system in real time, edited live (docs/viewer.md).
//
// The Viewer runs a host::Session frame by frame on a Surface (a window, or offscreen
// when headless): it steps the system (real time in fixed steps, or a step a frame;
// scaled, paused, one step at a time: tools/viewer/sim_clock.h), draws every type as its
// render command says (points, sprites, streaks: tools/viewer/particles.h) from the
// run-time's draw columns, in HDR with a glow (tools/viewer/glow.h; each type shown,
// hidden or solo), shows the panel
// (externs, triggers, time, backend), the stats and the keys, watches the file and
// everything it imports and hot-reloads on save (tools/viewer/reloader.h), and writes
// screenshots and recordings (tools/viewer/recorder.h).
#pragma once

#include <chrono>
#include <functional>
#include <map>
#include <set>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "camera.h"
#include "host/session.h"
#include "recorder.h"
#include "reloader.h"
#include "glow.h"
#include "particles.h"
#include "render.h"
#include "script.h"
#include "sim_clock.h"
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
    std::string screenshot;      // an image of the last frame
    std::string record;          // a folder (a PNG every `every` frames), or an .mp4 or .gif
    int every = 1;
    std::optional<Camera> camera;
    std::vector<host::ExternSetting> sets;
    std::vector<host::TriggerFiring> fires;
    host::SessionOptions session;
    double dt = 1.0 / 60;
    bool fixed = true;           // a step of dt a frame, not real time (headless, recording; main.cpp: a window runs real time)
    int maxSteps = 8;            // the most steps a real-time frame runs (a stall's catch-up)
    std::function<Clock::time_point()> now;  // the wall clock (tests give a fake one)
    int width = 1280, height = 720;
    Blend blend = Blend::Additive;  // of the types that name none (@blend)
    GlowSettings glow;
    bool ui = true;
    bool grid = true;
    bool fit = false;            // the camera fits what is alive before each frame is drawn
    bool watch = true;
    Script script;
    bool log = false;            // say on stdout what happens (reloads, their latency)
    double fps = 0;              // at most this many frames a second (0: as many as it can)
    double interimAfter = 0.05;
    int warmup = 0;              // frames left out of the summary --log prints
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
    // Draws the system as it is into the surface (the frame loop's drawing; tests call it).
    void draw();
    // Whether type `name` is drawn: not hidden, and the solo type if there is one.
    bool shows(const std::string& name) const;
    void hide(const std::string& type, bool hidden) { hidden ? (void)hidden_.insert(type) : (void)hidden_.erase(type); }
    void solo(const std::string& type) { solo_ = type; }  // "": every type not hidden

    host::Session& session() { return *session_; }
    const Camera& camera() const { return camera_; }
    const SimClock& clock() const { return clock_; }
    const Panel* panel() const { return panel_.get(); }
    // The frames during the last reload: the slowest, and a normal frame before it.
    struct Hitch {
        double worstSeconds = 0, normalSeconds = 0;
        int frames = 0;
    };
    const std::optional<Hitch>& lastHitch() const { return lastHitch_; }

private:
    friend class Panel;  // the panel shows and sets what the viewer runs
    struct FrameStats {
        double frameSeconds = 0, stepSeconds = 0, glSeconds = 0;
        int steps = 0;
        rt::Stats before, after;  // the run-time's stats around the frame's steps
    };

    void frame();
    void step(int steps, double seconds);
    Clock::time_point now() const { return options_.now ? options_.now() : Clock::now(); }
    void screenshotKey();
    void clipKey();
    bool record(const std::vector<uint8_t>& rgba);
    void stopRecording();
    void measureHitch(double frameSeconds);
    void handleReload();
    void restart(uint32_t seed);
    void watchSources(const host::CompileResult& compiled);
    void say(const std::string& line) const;
    void runScript();

    ViewerOptions options_;
    Surface& surface_;
    std::unique_ptr<host::Session> session_;
    Camera camera_;
    std::unique_ptr<ParticleRenderer> particles_;
    std::unique_ptr<SceneRenderer> scene_;
    std::unique_ptr<Glow> glow_;
    Watcher watcher_;
    std::unique_ptr<WorkerContext> workerContext_;  // the reloader's (outlives it)
    std::unique_ptr<Reloader> reloader_;
    std::unique_ptr<Panel> panel_;

    int frame_ = 0;                 // frames drawn (from 1)
    bool paused_ = false, stepOnce_ = false, quit_ = false;
    SimClock clock_;
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
    bool help_ = false;             // the keys over the frame (F1, ?)
    std::set<std::string> hidden_;  // types not drawn
    std::string solo_;              // the one type drawn, if not empty
    std::unique_ptr<Recorder> recorder_;  // --record, or a clip (V)
    bool clip_ = false;             // the recording is a clip the V key started
    bool fixedBeforeClip_ = false;  // the clock's mode before a clip fixed it
    int shotNumber_ = 0;            // the P key's last screenshot
    std::string shotNote_;          // what the last key's screenshot or clip did
    // The hitch of reloads: frames from a save to the new system's first frame.
    double normalFrame_ = 0;        // a smoothed frame time outside reloads
    std::optional<Hitch> hitch_, lastHitch_;
    bool hitchEnds_ = false;        // this frame shows the reload's last system
    int status_ = 0;
    // Sums over the frames drawn, for the summary --log prints at the end.
    struct Totals {
        int frames = 0;
        double frame = 0, step = 0, draw = 0;
    } totals_;
};

}  // namespace psys::viewer
