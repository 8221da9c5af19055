#include "viewer.h"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <thread>

#include <GLFW/glfw3.h>
#include <fmt/format.h>

#include "image_file.h"
#include "input.h"
#include "keys.h"
#include "panel.h"

namespace psys::viewer {

namespace {

double secondsBetween(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

// The rate of a recording: a frame every `every` steps of `dt` plays at the simulation's speed.
double recordingFps(double dt, int every) { return 1 / (dt * std::max(every, 1)); }

}  // namespace

Viewer::Viewer(ViewerOptions options, Surface& surface, std::unique_ptr<host::Session> session,
               host::CompileResult compiled)
    : options_(std::move(options)), surface_(surface), session_(std::move(session)) {
    camera_ = options_.camera.value_or(Camera{});
    workerContext_ = surface_.workerContext();
    particles_ = std::make_unique<ParticleRenderer>();
    scene_ = std::make_unique<SceneRenderer>();
    glow_ = std::make_unique<Glow>();
    reloader_ = std::make_unique<Reloader>(*session_, workerContext_.get());
    reloader_->interimAfterSeconds = options_.interimAfter;
    clock_ = SimClock({options_.dt, options_.fixed, 1, options_.maxSteps});
    lastCompileSeconds_ = compiled.seconds + session_->backend().report().compileSeconds;
    if (options_.watch) watchSources(compiled);
    if (surface_.window()) connectInput(surface_.window(), *this);  // before the panel's, which chain to them
    if (options_.ui) panel_ = std::make_unique<Panel>(*this, surface_);
    session_->schedule(options_.fires);  // checked by the caller (main.cpp) against this session
    if (!options_.startErrors.empty()) {
        diagnostics_ = options_.startErrors;
        reloadNote_ = "the file does not compile: save a fix and it starts";
    }
}

Viewer::~Viewer() = default;

void Viewer::say(const std::string& line) const {
    if (options_.log) std::cout << line << std::endl;
}

void Viewer::watchSources(const host::CompileResult& compiled) {
    std::vector<std::string> files = {session_->path()};
    if (compiled.sources)
        for (int f = 0; f < compiled.sources->count(); ++f) files.push_back(compiled.sources->file(f).path());
    watcher_.watch(files);
}

int Viewer::run() {
    int last = options_.frames > 0 ? options_.frames : (options_.headless ? 1 : 0);
    if (!options_.record.empty()) {
        std::string error;
        recorder_ = Recorder::open(options_.record, surface_.width(), surface_.height(),
                                   recordingFps(options_.dt, options_.every), error);
        if (!recorder_) {
            std::cerr << "psys-view: error: " << error << "\n";
            return 1;
        }
    }
    lastFrame_ = now();
    while (!quit_ && !surface_.closed() && (last == 0 || frame_ < last)) frame();
    if (!options_.screenshot.empty() && !screenshot(options_.screenshot)) status_ = 1;
    stopRecording();
    if (totals_.frames > 0) {
        size_t live = 0;
        for (const rt::TypeStats& t : session_->system().stats().types) live += t.live;
        double n = totals_.frames;
        say(fmt::format("{} frames drawn, {} objects live at the end: {:.2f} ms a frame (simulation {:.2f}, drawing {:.2f})",
                        totals_.frames, live, totals_.frame * 1e3 / n, totals_.step * 1e3 / n, totals_.draw * 1e3 / n));
    }
    return status_;
}

void Viewer::frame() {
    ++frame_;
    Clock::time_point start = Clock::now();
    if (surface_.window()) glfwPollEvents();
    if (options_.watch && watcher_.changed()) {
        reloader_->saved(Clock::now());
        if (!hitch_) hitch_ = Hitch{0, normalFrame_, 0};
    }
    handleReload();
    runScript();
    Clock::time_point wall = now();
    double real = secondsBetween(lastFrame_, wall);
    lastFrame_ = wall;
    stats_.before = session_->system().stats();
    auto stepStart = Clock::now();
    stats_.steps = 0;
    if (paused_) clock_.resetDebt();  // a pause owes no catch-up
    if (!paused_ || stepOnce_) {
        stats_.steps = paused_ ? clock_.stepOnce() : clock_.advance(real);
        step(stats_.steps, clock_.stepSeconds());
        stepOnce_ = false;
    }
    stats_.stepSeconds = secondsBetween(stepStart, Clock::now());
    stats_.after = session_->system().stats();
    // Offscreen, only the frames that are written are drawn (and, with the panel, every
    // frame: it lays itself out over a few).
    bool recorded = recorder_ && frame_ % std::max(clip_ ? 1 : options_.every, 1) == 0;
    bool shown = surface_.window() || panel_ || frame_ == options_.frames || options_.frames <= 0 || !shots_.empty() ||
                 recorded;
    if (shown) {
        if (options_.fit) frameAlive();
        draw();
        if (panel_) panel_->draw();
        surface_.present();
    }
    for (const std::string& shot : shots_)
        if (!screenshot(shot)) status_ = 1;
    shots_.clear();
    if (recorded && !record(surface_.pixels())) {
        status_ = 1;  // a recording with a frame missing is no recording: stop
        if (!clip_) quit_ = true;
    }
    stats_.frameSeconds = secondsBetween(start, Clock::now());
    if (reloadSaved_) {  // the first frame of a reloaded system is out
        lastReloadSeconds_ = secondsBetween(*reloadSaved_, Clock::now());
        say(fmt::format("first frame of the new system {:.1f} ms after the save", *lastReloadSeconds_ * 1e3));
        reloadSaved_.reset();
    }
    if (shown && frame_ > options_.warmup) {
        ++totals_.frames;
        totals_.frame += stats_.frameSeconds;
        totals_.step += stats_.stepSeconds;
        totals_.draw += stats_.glSeconds;
    }
    if (options_.fps > 0) {
        double rest = 1 / options_.fps - stats_.frameSeconds;
        if (rest > 0) std::this_thread::sleep_for(std::chrono::duration<double>(rest));
    }
    measureHitch(secondsBetween(start, Clock::now()));  // as a person sees it: with the wait for the next
    fps_ = fps_ == 0 ? 1 / std::max(stats_.frameSeconds, 1e-6) : 0.9 * fps_ + 0.1 / std::max(stats_.frameSeconds, 1e-6);
}

// A frame's time, for the hitch of a reload: during one, the slowest; outside, a smoothed
// normal frame to compare it with.
// (a vsync or --fps), from the save to the frame that shows the system the reload ends on
// (after an interim on the interpreter, the JIT's).
void Viewer::measureHitch(double frameSeconds) {
    if (!hitch_) {
        normalFrame_ = normalFrame_ == 0 ? frameSeconds : 0.95 * normalFrame_ + 0.05 * frameSeconds;
        return;
    }
    hitch_->worstSeconds = std::max(hitch_->worstSeconds, frameSeconds);
    ++hitch_->frames;
    if (!hitchEnds_) return;
    hitchEnds_ = false;
    lastHitch_ = hitch_;
    hitch_.reset();
    say(fmt::format("reload hitch: the slowest of its {} frames {:.1f} ms, a normal frame {:.1f} ms ({:.2f}x)",
                    lastHitch_->frames, lastHitch_->worstSeconds * 1e3, lastHitch_->normalSeconds * 1e3,
                    lastHitch_->worstSeconds / std::max(lastHitch_->normalSeconds, 1e-9)));
}

void Viewer::step(int steps, double seconds) {
    if (auto error = session_->frame(frame_, seconds, steps)) {
        say("psys-view: " + *error);
        status_ = 1;
    }
}

// What the reloader finished this frame, if anything: the new system, or the errors.
void Viewer::handleReload() {
    auto outcome = reloader_->poll();
    if (!outcome) return;
    using Kind = Reloader::Outcome::Kind;
    auto saved = Clock::now() - std::chrono::duration_cast<Clock::duration>(
                                    std::chrono::duration<double>(outcome->latencySeconds));
    watchSources(outcome->compile);
    if (outcome->kind != Kind::Adopted && outcome->kind != Kind::Interim) hitch_.reset();  // nothing new to show
    hitchEnds_ = outcome->kind == Kind::Adopted;
    if (outcome->kind == Kind::Empty || outcome->kind == Kind::Vanished) {
        reloadNote_ = "`" + session_->path() + "`" +
                      (outcome->kind == Kind::Empty ? " is empty (a save under way?): the system keeps running"
                                                    : " is gone (deleted or renamed): the system keeps running until it returns");
        say("reload: " + reloadNote_);
        return;
    }
    if (outcome->kind == Kind::Failed) {
        diagnostics_ = outcome->compile.text();
        reloadNote_ = "the edit does not compile: the system keeps running";
        say(fmt::format("reload failed {:.1f} ms after the save:\n{}", outcome->latencySeconds * 1e3, diagnostics_));
        return;
    }
    diagnostics_.clear();
    const rt::ReloadReport& r = *outcome->report;
    std::string what = fmt::format("{} objects carried over", r.carried);
    if (r.dropped) what += fmt::format(", {} dropped", r.dropped);
    if (!r.newSlots.empty()) what += fmt::format(", {} new slots", r.newSlots.size());
    if (!r.lostSlots.empty()) what += fmt::format(", {} slots lost", r.lostSlots.size());
    if (!r.spawned.empty()) what += fmt::format(", {} new spawns", r.spawned.size());
    if (outcome->kind == Kind::Interim) {
        reloadNote_ = what + "; on the interpreter until the JIT is ready";
        say(fmt::format("reload: the new system {:.1f} ms after the save, on the interpreter until the JIT is ready: {}",
                        outcome->latencySeconds * 1e3, what));
        reloadSaved_ = saved;
        interim_ = true;
        return;
    }
    lastCompileSeconds_ = outcome->compile.seconds + outcome->prepareSeconds;
    reloadNote_ = what;
    std::string where = outcome->frameSlices
                            ? fmt::format(", {} frames of it on the frame loop", outcome->frameSlices)
                            : "";
    say(fmt::format("reload: the new system {:.1f} ms after the save (front end {:.1f} ms, kernels {:.1f} ms{}){}: {}",
                    outcome->latencySeconds * 1e3, outcome->compile.seconds * 1e3, outcome->prepareSeconds * 1e3, where,
                    interim_ ? ", now on the JIT" : "", what));
    if (!interim_) reloadSaved_ = saved;  // after an interim, the new system is already showing
    interim_ = false;
}

void Viewer::draw() {
    auto start = Clock::now();
    surface_.bind();
    GLint target = 0;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &target);
    glow_->begin(surface_.width(), surface_.height());
    clearFrame();
    float aspect = static_cast<float>(surface_.width()) / static_cast<float>(std::max(surface_.height(), 1));
    glm::mat4 view = camera_.view(), projection = camera_.projection(aspect);
    scene_->draw(view, projection, options_.grid);
    rt::System& system = session_->system();
    // Alpha-blended matter first (each type back to front), then added light over it.
    for (core::Blend pass : {core::Blend::Alpha, core::Blend::Add})
        for (size_t t = 0; t < system.typeCount(); ++t) {
            const ir::Object& o = system.module().objects[t];
            DrawStyle style{o.draw,
                            o.attributes.shape.value_or(core::Shape::Soft),
                            o.attributes.blend.value_or(options_.blend == Blend::Alpha ? core::Blend::Alpha : core::Blend::Add),
                            o.attributes.texture,
                            o.attributes.textureColumns,
                            o.attributes.textureRows,
                            options_.grid};
            if (style.blend == pass && shows(o.name))
                particles_->draw(system.draw(t), system.backend().memory(), style, view, projection,
                                 static_cast<float>(surface_.height()));
        }
    glow_->finish(static_cast<GLuint>(target), options_.glow);
    if (std::string problems = particles_->takeProblems(); !problems.empty())
        std::fprintf(stderr, "psys-view: %s", problems.c_str());
    stats_.glSeconds = secondsBetween(start, Clock::now());
}

void Viewer::key(int key, bool shift) {
    switch (key) {
        case GLFW_KEY_F: frameAlive(); break;
        case GLFW_KEY_R: camera_.reset(); break;
        case GLFW_KEY_B: options_.blend = options_.blend == Blend::Additive ? Blend::Alpha : Blend::Additive; break;
        case GLFW_KEY_G: options_.grid = !options_.grid; break;
        case GLFW_KEY_L: options_.glow.on = !options_.glow.on; break;
        case GLFW_KEY_SPACE: paused_ = !paused_; break;
        case GLFW_KEY_S: stepOnce_ = true; break;
        case GLFW_KEY_T:
            clock_.settings().fixed = !clock_.settings().fixed;
            clock_.resetDebt();
            break;
        case GLFW_KEY_EQUAL: case GLFW_KEY_KP_ADD: clock_.settings().scale = std::min(clock_.settings().scale * 2, 16.0); break;
        case GLFW_KEY_MINUS: case GLFW_KEY_KP_SUBTRACT:
            clock_.settings().scale = std::max(clock_.settings().scale / 2, 1.0 / 64);
            break;
        case GLFW_KEY_H: if (panel_) panel_->visible = !panel_->visible; break;
        case GLFW_KEY_F1: help_ = !help_; break;
        case GLFW_KEY_SLASH: if (shift) help_ = !help_; break;
        case GLFW_KEY_P: screenshotKey(); break;
        case GLFW_KEY_V: clipKey(); break;
        case GLFW_KEY_ESCAPE: case GLFW_KEY_Q: quit_ = true; break;
        default:
            if (key >= GLFW_KEY_1 && key <= GLFW_KEY_9) {
                auto index = static_cast<size_t>(key - GLFW_KEY_1);
                const auto& triggers = session_->system().module().triggers;
                if (index < triggers.size()) {
                    std::vector<float> args = panel_ ? panel_->triggerArgs(index) : std::vector<float>{};
                    if (args.empty())
                        for (const ir::Param& p : triggers[index].hostParams()) args.resize(args.size() + static_cast<size_t>(p.type.width), 0);
                    fire(triggers[index].name, args);
                }
            }
    }
}

// Fits what is alive in view: the box of the drawn points, without the farthest 2% on
// each side of each axis (a few strays do not shrink the rest to a dot).
void Viewer::frameAlive() {
    rt::System& system = session_->system();
    std::vector<float> axis[3];
    for (size_t t = 0; t < system.typeCount(); ++t)
        if (shows(system.module().objects[t].name))
            for (const rt::RenderPoint& p : system.points(t))
            for (int c = 0; c < 3; ++c) axis[c].push_back(p.position[static_cast<size_t>(c)]);
    if (axis[0].empty()) return;
    glm::vec3 low, high;
    for (int c = 0; c < 3; ++c) {
        std::vector<float>& v = axis[c];
        size_t lo = v.size() / 50, hi = v.size() - 1 - v.size() / 50;
        std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(lo), v.end());
        low[c] = v[lo];
        std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(hi), v.end());
        high[c] = v[hi];
    }
    camera_.frame(low, high);
}

std::optional<std::string> Viewer::set(const host::ExternSetting& setting) { return session_->apply(setting); }

std::optional<std::string> Viewer::fire(const std::string& trigger, const std::vector<float>& args) {
    auto error = session_->system().fire(trigger, args);
    if (error) std::cerr << "psys-view: error: " << *error << "\n";
    return error;
}

bool Viewer::screenshot(const std::string& path) {
    if (auto problem = writeImage(path, surface_.width(), surface_.height(), surface_.pixels())) {
        std::cerr << "psys-view: error: cannot write `" << path << "`: " << *problem << "\n";
        return false;
    }
    say("wrote " + path);
    return true;
}

bool Viewer::shows(const std::string& name) const {
    return solo_.empty() ? !hidden_.count(name) : name == solo_;
}

// P: FILE's name and the first number not taken, .png, in the current folder.
void Viewer::screenshotKey() {
    std::string stem = std::filesystem::path(session_->path()).stem().string();
    std::string path;
    std::error_code ignored;
    do path = fmt::format("{}_{:03}.png", stem, ++shotNumber_);
    while (std::filesystem::exists(path, ignored));
    shots_.push_back(path);  // once the frame is drawn
    shotNote_ = "screenshot " + path;
}

// V: a clip, from now to the next V: an .mp4 where ffmpeg is, else a folder of PNGs. While
// it records, the clock runs a fixed step a frame, so the clip plays at the simulation's speed.
void Viewer::clipKey() {
    if (recorder_) {
        if (!clip_) {
            shotNote_ = "--record's recording runs to the end";
            return;
        }
        stopRecording();
        return;
    }
    std::string stem = std::filesystem::path(session_->path()).stem().string();
    bool video = Recorder::haveFfmpeg();
    std::string path;
    std::error_code ignored;
    for (int n = 1;; ++n) {
        path = fmt::format("{}_clip_{:03}{}", stem, n, video ? ".mp4" : "");
        if (!std::filesystem::exists(path, ignored)) break;
    }
    std::string error;
    recorder_ = Recorder::open(path, surface_.width(), surface_.height(), recordingFps(options_.dt, 1), error);
    if (!recorder_) {
        shotNote_ = error;
        std::cerr << "psys-view: error: " << error << "\n";
        return;
    }
    clip_ = true;
    fixedBeforeClip_ = clock_.settings().fixed;
    clock_.settings().fixed = true;
    shotNote_ = "recording " + path + " (V stops)";
    say("recording " + path);
}

bool Viewer::record(const std::vector<uint8_t>& rgba) {
    if (auto error = recorder_->add(frame_, rgba)) {
        std::cerr << "psys-view: error: " << *error << "\n";
        shotNote_ = *error;
        recorder_->finish();
        recorder_.reset();
        if (clip_) clock_.settings().fixed = fixedBeforeClip_;
        clip_ = false;
        return false;
    }
    return true;
}

void Viewer::stopRecording() {
    if (!recorder_) return;
    if (auto error = recorder_->finish()) {
        std::cerr << "psys-view: error: " << *error << "\n";
        shotNote_ = *error;
        status_ = 1;
    } else {
        shotNote_ = fmt::format("wrote {} ({} frames)", recorder_->path(), recorder_->frames());
        say(shotNote_);
    }
    if (clip_) {
        clock_.settings().fixed = fixedBeforeClip_;
        clock_.resetDebt();
    }
    clip_ = false;
    recorder_.reset();
}

void Viewer::restart(uint32_t seed) {
    host::SessionOptions options = session_->options();
    options.system.seed = seed;
    host::CompileResult compiled;
    std::string error;
    auto fresh = host::Session::open(session_->path(), options, compiled, error);
    if (!fresh) {
        diagnostics_ = compiled.ok ? error : compiled.text();
        return;
    }
    // Extern values set in the panel stay.
    const rt::System& old = session_->system();
    for (const ir::Extern& e : old.module().externs)
        if (auto v = old.externValue(e.name))
            fresh->system().setExtern(e.name, std::span<const float>(v->f.data(), static_cast<size_t>(e.type.width)));
    reloader_.reset();
    session_ = std::move(fresh);
    reloader_ = std::make_unique<Reloader>(*session_, workerContext_.get());
    frame_ = 0;
}

void Viewer::runScript() {
    for (const ScriptAction& a : options_.script.actions) {
        if (a.frame != frame_) continue;
        const auto& w = a.words;
        const auto& n = a.numbers;  // (checked when the script was read)
        if (a.verb == "orbit") orbit(n[0], n[1]);
        else if (a.verb == "pan") pan(n[0], n[1]);
        else if (a.verb == "zoom") zoom(n[0]);
        else if (a.verb == "quit") quit_ = true;
        else if (a.verb == "screenshot") shots_.push_back(w[0]);  // once the frame is drawn
        else if (a.verb == "key") {
            KeyPress press = *keyPress(w[0]);  // (a key of keys.h: checked when read)
            key(press.code, press.shift);
        } else if (a.verb == "set") {
            auto setting = host::parseSet(w[0]);
            auto error = setting ? set(*setting) : std::optional<std::string>(setting.error);
            if (error) {
                std::cerr << "psys-view: error: script, frame " << a.frame << ": " << *error << "\n";
                status_ = 1;
            }
        } else if (a.verb == "fire") {
            auto firing = host::parseFire(w[0] + "@1");
            if (!firing || fire(firing->trigger, firing->args)) status_ = 1;
        }
    }
}

}  // namespace psys::viewer
