// A running system as a host holds it: compiled from a file (through driver/), on a
// backend chosen by name, with the host's settings applied, stepped frame by frame — and
// hot-reloaded: compile the file again and, if it compiles, a new system takes over the
// running one's objects (rt::System::carryOver); if it does not, the old one keeps
// running and the diagnostics say why. psysc run, the viewer and the benchmarks are
// users of this.
#pragma once

#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "driver/compile.h"
#include "host/backends.h"
#include "host/settings.h"
#include "rt/system.h"
#include "tune/tolerance.h"

namespace psys::host {

struct SessionOptions {
    BackendChoice backend;
    CompileOptions compile;
    rt::SystemOptions system;
    // The chooser under @tolerance (tune/tolerance.h): its frame, a default tolerance.
    tune::TuneOptions tune;
    // Whether the system may be hot-reloaded: then it is compiled so that its state is the
    // program's own whatever the maths (opt::PassOptions::reloadable), and a reload under
    // fast maths carries what one under exact maths does. A host that never reloads
    // (psysc run) says so, and its fast maths gets the closed forms.
    bool reloadable = true;
};

// Installs the chooser of integrators and steps under @tolerance in `options`, compiled
// with `options`' passes; its trials run where the system will — the LLVM JIT with its
// maths for `llvm` (fast maths rounds differently, and over a long run that is the error),
// else the interpreter (the GPU's IEEE float). What it chose goes to `choices`.
void chooseUnderTolerance(CompileOptions& options, tune::TuneOptions tune, const BackendChoice& runsOn,
                          std::shared_ptr<std::vector<tune::Choice>> choices = {});

// The outcome of one compilation: its diagnostics (errors and warnings, with their
// sources), whether it produced a module, and how long it took.
struct CompileResult {
    std::shared_ptr<SourceManager> sources;
    std::shared_ptr<DiagnosticEngine> diagnostics;
    bool ok = false;
    double seconds = 0;
    void print(std::ostream& out, bool colour) const;
    std::string text() const;  // the diagnostics without colour
};

// Compiles a file (or a text standing for it) to a module.
CompileResult compile(const std::string& path, const CompileOptions& options, std::optional<ir::Module>& module,
                      const std::string* text = nullptr);

class Session {
public:
    // Compiles `path` (or `text`, standing for it) and starts a system on the chosen
    // backend; null when it does not compile or the backend cannot be made (`result`, `error`).
    static std::unique_ptr<Session> open(const std::string& path, const SessionOptions& options, CompileResult& result,
                                         std::string& error, const std::string* text = nullptr);
    // The same in two halves, for a host that compiles on a thread of its own (a large
    // stack) and runs on another (a GL context's): what `options` compile with, and a
    // session started with a module compiled so.
    static SessionOptions resolved(const SessionOptions& options);
    static std::unique_ptr<Session> start(const std::string& path, const SessionOptions& resolved, ir::Module module,
                                          std::string& error);
    ~Session();

    rt::System& system() { return *system_; }
    const rt::System& system() const { return *system_; }
    rt::Backend& backend() { return *backend_; }
    const SessionOptions& options() const { return options_; }
    const std::string& path() const { return path_; }

    std::optional<std::string> apply(const ExternSetting& setting);
    std::optional<std::string> fire(const TriggerFiring& firing);
    // Triggers fired before the frames they name (frame() below).
    // Triggers to fire before given frames. Each must name a trigger of the system with
    // its number of values, at a frame from 1 to `lastFrame` (0: no last frame); else an
    // error names the first that does not, and nothing is scheduled.
    std::optional<std::string> schedule(std::vector<TriggerFiring> firings, int lastFrame = 0);
    // Frame `index` (from 1): the triggers scheduled for it, then `steps` steps of `dt`
    // (a real-time host runs none, one or several a frame).
    std::optional<std::string> frame(int index, double dt, int steps = 1);
    double stepSeconds() const { return stepSeconds_; }  // in frame(), so far

    struct Reload {
        CompileResult compile;
        std::optional<rt::ReloadReport> report;  // when it compiled and took over
    };
    // Compiles the file again (or `text`); on success the new system takes over.
    Reload reload(const std::string* text = nullptr);

    // The same in two halves, for a host that keeps running while it compiles: a candidate
    // is compiled, and the backend prepared for it (its kernels compiled), on any thread;
    // `adopt` makes it take over, on its backend, on the thread that runs the session.
    struct Candidate {
        CompileResult compile;
        std::optional<ir::Module> module;
        std::shared_ptr<rt::Backend> backend;  // the backend it was prepared for
        double prepareSeconds = 0;             // compiling its kernels
    };
    Candidate compileCandidate(const std::string* text = nullptr) const;
    Reload adopt(Candidate candidate);
    std::shared_ptr<rt::Backend> backendHandle() const { return backend_; }
    // The running system's objects on another backend.
    std::optional<std::string> switchBackend(const BackendChoice& choice);

private:
    Session() = default;

    std::string path_;
    SessionOptions options_;
    std::shared_ptr<rt::Backend> backend_;
    std::unique_ptr<rt::System> system_;
    std::vector<TriggerFiring> scheduled_;
    double stepSeconds_ = 0;
};

}  // namespace psys::host
