// Hot reload off the frame loop. On save, a worker thread compiles the file and prepares
// the JIT for it (compiles its kernels) while the old system keeps running; the frame loop
// adopts the result at a frame boundary (host::Session::adopt: the objects carry over). A
// backend that can only prepare on the frame loop's thread (the GLSL backend) is prepared
// there a slice a frame before the new system takes over, so no frame compiles them all. If
// the JIT is still compiling a while after the module is ready, the new system runs on the
// interpreter meanwhile and moves to the JIT when its kernels are ready: the objects carry
// over both times. A file that does not compile leaves the old system running, and so
// does one that is empty (an editor that truncates, then writes, is seen in between) or
// gone (deleted or renamed: its return is a save like any other).
#pragma once

#include <chrono>
#include <mutex>
#include <optional>
#include <thread>

#include "host/session.h"
#include "surface.h"

namespace psys::viewer {

using Clock = std::chrono::steady_clock;

class Reloader {
public:
    // `worker`: a context sharing the viewer's, where a GLSL backend's programs are compiled
    // off the frame loop (null: on it, a slice a frame).
    explicit Reloader(host::Session& session, WorkerContext* worker = nullptr) : session_(session), context_(worker) {}
    ~Reloader();
    Reloader(const Reloader&) = delete;
    Reloader& operator=(const Reloader&) = delete;

    // A watched file was saved (at `when`): compile it now, or after the compile under way.
    void saved(Clock::time_point when);
    bool busy() const { return worker_.joinable() || ready_; }

    struct Outcome {
        enum class Kind { Adopted, Interim, Failed, Empty, Vanished } kind;
        host::CompileResult compile;
        std::optional<rt::ReloadReport> report;
        double latencySeconds = 0;  // from the save to the new system taking over
        double prepareSeconds = 0;  // compiling its kernels
        int frameSlices = 0;        // frames that compiled a part of them on the frame loop (prepareSome)
    };
    // Once per frame, on the frame loop's thread: what changed, if anything.
    std::optional<Outcome> poll();
    // How long a module may wait for the JIT before it runs on the interpreter meanwhile.
    double interimAfterSeconds = 0.05;
    // What a frame spends preparing a backend that cannot prepare off the frame loop (the
    // GLSL backend: a GL context is one thread's): a program a frame past this.
    double sliceSeconds = 0.004;

private:
    void start(Clock::time_point when);
    // The worker's body: compile `path` and prepare the backend; the result for poll().
    int work(const std::string& path, const host::SessionOptions& options, std::shared_ptr<rt::Backend> backend);
    void finish();

    host::Session& session_;
    WorkerContext* context_;
    std::thread worker_;
    std::mutex mutex_;
    // What the worker produced, under mutex_.
    bool compiled_ = false, prepared_ = false;
    host::CompileResult compile_;
    std::optional<ir::Module> interimModule_;
    host::Session::Candidate candidate_;
    Clock::time_point savedAt_;
    bool interim_ = false;                      // the new system runs on the interpreter meanwhile
    std::optional<Outcome::Kind> kept_;         // the file was empty or gone: nothing compiled
    std::optional<Clock::time_point> pending_;  // a save during the compile
    // A compiled candidate whose backend is being prepared on the frame loop, a slice a
    // frame (Backend::prepareSome), and its plan.
    std::optional<host::Session::Candidate> ready_;
    rt::Plan readyPlan_;
    int readySlices_ = 0;  // its frames that compiled something
    Clock::time_point readySaved_;
};

}  // namespace psys::viewer
