#include "run_command.h"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <iostream>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "host/session.h"

namespace psys::tools {
namespace {

// `--dump`: every drawn point of the frames dumped, written as each frame ends (CSV rows,
// or a JSON document {"frames": [...]} streamed one frame a line), so memory stays that of
// one frame however long the run; the file is opened before the run starts. A trail's
// points behind its head: JSON "trail": [[x, y, z], …], the CSV's last column `x y z x y z …`.
class Dump {
public:
    explicit Dump(const std::string& path) : path_(path), json_(path.ends_with(".json")) {
        if (path.empty()) return;
        out_.open(path, std::ios::binary);
        out_ << (json_ ? "{\"frames\": [" : "frame,time,type,id,x,y,z,r,g,b,a,size,rotation,sprite_frame,end_x,end_y,end_z,trail\n");
    }
    bool ok() const { return path_.empty() || out_.good(); }

    void frame(int frame, rt::System& system) {
        if (path_.empty()) return;
        if (json_) out_ << (frames_++ ? ",\n" : "\n") << fmt::format(R"({{"frame": {}, "time": {}, "objects": [)", frame,
                                                                     nlohmann::json(system.time()).dump());
        bool first = true;
        for (size_t t = 0; t < system.typeCount(); ++t) {
            const std::string& type = system.module().objects[t].name;
            for (const rt::RenderPoint& p : system.points(t)) {
                if (json_) {
                    nlohmann::json o = {{"type", type}, {"id", p.id}, {"position", p.position}, {"color", p.color}, {"size", p.size}};
                    if (system.module().objects[t].draw == core::DrawKind::Sprite) {
                        o["rotation"] = p.rotation;
                        o["frame"] = p.frame;
                    }
                    if (system.module().objects[t].draw == core::DrawKind::Streak) o["end"] = p.end;
                    if (system.module().objects[t].draw == core::DrawKind::Trail) o["trail"] = p.trail;
                    out_ << (first ? "" : ", ") << o.dump();
                    first = false;
                } else {
                    std::string trail;
                    for (const auto& q : p.trail) trail += fmt::format("{}{} {} {}", trail.empty() ? "" : " ", q[0], q[1], q[2]);
                    out_ << fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", frame, system.time(), type,
                                        p.id, p.position[0], p.position[1], p.position[2], p.color[0], p.color[1],
                                        p.color[2], p.color[3], p.size, p.rotation, p.frame, p.end[0], p.end[1],
                                        p.end[2], trail);
                }
            }
        }
        if (json_) out_ << "]}";
        out_.flush();
    }

    bool finish() {
        if (path_.empty()) return true;
        if (json_) out_ << "\n]}\n";
        out_.close();
        return !out_.fail();
    }

private:
    std::string path_;
    bool json_;
    std::ofstream out_;
    size_t frames_ = 0;
};

void printSummary(const RunOptions& options, host::Session& session, double drawSeconds, int ran) {
    rt::System& system = session.system();
    system.finish();  // the last step's kills a GPU still owes: the summary is exact
    rt::Stats stats = system.stats();
    if (options.timing) {
        rt::BackendReport r = session.backend().report();
        if (r.kernels > 0 || r.cacheHits > 0)
            std::cout << fmt::format("compiled {} kernels in {:.1f} ms ({}, {} math{})\n", r.kernels,
                                     r.compileSeconds * 1e3, r.target, options.math,
                                     r.fromDisk ? fmt::format("; {} from the disk cache", r.fromDisk) : "");
        int frames = std::max(ran, 1);
        std::string folds = stats.folds ? fmt::format(", neighbour folds {:.3f}", stats.foldSeconds * 1e3 / frames) : "";
        std::cout << fmt::format("stepping {:.3f} ms per frame (update loops {:.3f}, kills and emissions {:.3f}, "
                                 "creation {:.3f}{}), drawing {:.3f} ms per frame\n",
                                 session.stepSeconds() * 1e3 / frames, stats.loopSeconds * 1e3 / frames,
                                 stats.emitSeconds * 1e3 / frames, stats.createSeconds * 1e3 / frames, folds,
                                 drawSeconds * 1e3 / frames);
        if (r.device)
            std::cout << fmt::format("on the GPU: the host waited for it {:.1f} times a frame, and took {:.1f} "
                                     "read-backs a frame later, when they were needed ({:.1f} not ready); {:.1f} KB a frame "
                                     "between host and GPU, {:.1f} KB copied on the GPU; {:.1f} launches a frame ran on the "
                                     "host (pools of few rows, their columns there)\n",
                                     static_cast<double>(r.waits) / frames, static_cast<double>(r.lateReads) / frames,
                                     static_cast<double>(r.lateStalls) / frames,
                                     static_cast<double>(r.transferredBytes) / 1024 / frames,
                                     static_cast<double>(r.stagedBytes) / 1024 / frames,
                                     static_cast<double>(r.hostLaunches) / frames);
    }
    std::cout << fmt::format("after {} frames ({:.3f} s){}:\n", ran, system.time(),
                             system.finished() ? ", finished (nothing alive, nothing to create)" : "");
    for (auto& t : stats.types)
        std::cout << fmt::format("  {:24} live {:8}  created {:10}  killed {:10}  frozen {:4}  dropped {}\n", t.name,
                                 t.live, t.created, t.killed, t.frozen, t.dropped);
    for (auto& t : stats.types)
        if (t.unstable)
            std::cout << fmt::format("  {}: {} updates beyond what its integration method holds (a decay rate k "
                                     "with k·dt past the stability limit: the integral oscillates and grows; or, "
                                     "under bs3, an error past the tolerance in an update's last try); use @step or "
                                     "@integrator(exponential)\n",
                                     t.name, t.unstable);
    for (auto& t : stats.types)
        if (t.cappedSubSteps)
            std::cout << fmt::format("  {}: {} updates needed more than 10000 @step sub-steps and took 10000 longer "
                                     "ones\n", t.name, t.cappedSubSteps);
    if (stats.rejectedSteps || stats.nonFiniteExterns || stats.invalidEmissions || stats.nonFiniteRender)
        std::cout << fmt::format("  rejected steps {}, non-finite extern values {}, invalid emissions {}, "
                                 "points not drawn (non-finite) {}\n",
                                 stats.rejectedSteps, stats.nonFiniteExterns, stats.invalidEmissions,
                                 stats.nonFiniteRender);
    if (stats.clampedEmissions)
        std::cout << fmt::format("  emissions asking for more than 1e18 objects (taken as 1e18): {}\n",
                                 stats.clampedEmissions);
}

}  // namespace

int runSystem(const RunOptions& options) {
    // Bad usage (a flag, a setting, a firing the program does not take) is exit 2; a run
    // that fails (a backend that cannot be made, a frame, a file that cannot be written) 1.
    auto fail = [](const std::string& message) {
        std::cerr << "psysc: error: " << message << "\n";
        return 2;
    };
    auto failed = [](const std::string& message) {
        std::cerr << "psysc: error: " << message << "\n";
        return 1;
    };
    auto dt = host::parseStep(options.dt);
    if (!dt) return fail(dt.error);
    std::vector<host::ExternSetting> sets;
    for (const std::string& s : options.sets) {
        auto set = host::parseSet(s);
        if (!set) return fail(set.error);
        sets.push_back(*set);
    }
    std::vector<host::TriggerFiring> fires;
    for (const std::string& f : options.fires) {
        auto fire = host::parseFire(f);
        if (!fire) return fail(fire.error);
        fires.push_back(*fire);
    }

    host::SessionOptions session;
    session.backend = {options.backend, options.math};
    session.compile.pipeline.optimize = options.optimize;
    session.compile.pipeline.pass.relaxed = options.relaxed;
    session.compile.pipeline.pass.everyObject = options.integrator;
    session.tune.frame = *dt;
    session.tune.tolerance = options.tolerance;
    session.system.seed = options.seed;
    session.system.capacity = options.capacity;
    session.system.threads = options.threads;
    using Rows = rt::SystemOptions::Rows;
    session.system.rows = options.rows == "memory" ? Rows::InMemory : options.rows == "host" ? Rows::OnHost : Rows::AsBackend;
    // (A type drawn as the step goes keeps its rows on the host: where the rows are asked
    // for in the memory, the CPU backends draw after the step, as the GPU does.)
    if (options.rows == "memory") session.system.drawInStep = false;
    session.reloadable = false;  // a run never reloads
    host::CompileResult compiled;
    std::string error;
    auto s = host::Session::open(options.file, session, compiled, error);
    compiled.print(std::cerr, options.colour);
    if (!compiled.ok) return 1;
    if (!s) return failed(error);
    if (options.printSchedule) {
        std::cout << fmt::format("A step of {} ({} backend), phase by phase:\n", options.file, options.backend)
                  << rt::printSchedule(s->system().schedule());
        return 0;
    }
    if (options.remarks) {
        rt::BackendReport report = s->backend().report();
        for (const auto& r : report.remarks)
            std::cout << fmt::format("{}: {}: {}\n", r.loop, r.vectorized ? "vectorized" : "not vectorized", r.message);
        if (!report.calls.empty()) std::cout << fmt::format("library calls: {}\n", fmt::join(report.calls, " "));
    }
    for (const host::ExternSetting& set : sets)
        if (auto e = s->apply(set)) return fail("--set " + set.name + ": " + *e);
    if (auto e = s->schedule(fires, options.frames)) return fail(*e);
    Dump dump(options.dump);
    if (!dump.ok()) return failed("cannot write `" + options.dump + "`");
    rt::System& system = s->system();
    double drawSeconds = 0;
    int lastFire = 0;  // (--until-finished: not before the last firing)
    for (const host::TriggerFiring& f : fires) lastFire = std::max(lastFire, f.frame);
    int ran = 0;
    for (int frame = 1; frame <= options.frames; ++frame) {
        ran = frame;
        if (auto e = s->frame(frame, *dt)) return failed(*e);
        if (!options.quiet) {
            std::string line = fmt::format("frame {:4}  t={:.4f}", frame, system.time());
            for (auto& t : system.stats().types) line += fmt::format("  {} {}", t.name, t.live);
            std::cout << line << "\n";
        }
        if (options.events) {
            std::vector<float> values;
            size_t width = 0;
            for (const std::string& name : system.eventNames()) {
                if (auto e = system.events(name, values, width)) return failed(*e);
                for (size_t k = 0; width > 0 && k < values.size(); k += width)
                    std::cout << fmt::format("event {} at frame {}: {}\n", name, frame,
                                             fmt::join(values.begin() + static_cast<std::ptrdiff_t>(k),
                                                       values.begin() + static_cast<std::ptrdiff_t>(k + width), " "));
            }
        }
        // Every frame is drawn (as a host would), so points with NaN or infinite values
        // are counted even when nothing is dumped.
        auto start = std::chrono::steady_clock::now();
        for (size_t t = 0; t < system.typeCount(); ++t) system.draw(t);
        drawSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (options.dumpEvery > 0 && frame % options.dumpEvery == 0) {
            dump.frame(frame, system);
            if (!dump.ok()) return failed("cannot write `" + options.dump + "` (at frame " + std::to_string(frame) + ")");
        }
        if (options.untilFinished && frame >= lastFire && system.finished()) break;
    }
    if (!dump.finish()) return failed("cannot write `" + options.dump + "`");
    printSummary(options, *s, drawSeconds, ran);
    return 0;
}

}  // namespace psys::tools
