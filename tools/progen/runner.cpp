#include "tools/progen/runner.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <memory>
#include <span>

#include <fmt/format.h>

#include "codegen_llvm/llvm_backend.h"
#include "driver/compile.h"
#include "gpu/glsl_backend.h"
#include "interp/interpreter.h"
#include "rt/system.h"

namespace psys::progen {

namespace {

// Rows are compared every this many frames (after finish(): what a device still owes taken
// first), and at the end. Between, a device's kills may be a step late in the rows (never
// in what is drawn).
constexpr int kRowsEvery = 10;
// Frames over which values are compared where objects fold over their neighbours (a crowd
// is chaotic: tests/run_length.h, kCrowdRun); what is alive is compared over every frame.
constexpr int kCrowdFrames = 20;

std::vector<Config> allConfigs() {
    return {
        {"interp", "interp", true, 1, true},
        {"llvm-exact-1t", "llvm", true, 1, true},
        {"llvm-exact-2t", "llvm", true, 2, true},
        {"llvm-fast-2t", "llvm", false, 2, true},
        {"glsl", "glsl", true, 1, true},
        {"glsl-device", "glsl", true, 1, false},
        {"interp-memory", "interp", true, 1, true, true},
    };
}

struct Side {
    Config config;
    std::shared_ptr<rt::Backend> backend;
    std::unique_ptr<rt::System> system;
    std::vector<rt::InstanceHandle> played;  // the case's plays, in order
};

// A case with an edit reloads: its systems are compiled as a host that reloads compiles
// them (opt::PassOptions::reloadable).
std::optional<ir::Module> compile(const std::string& text, bool relaxed, bool reloadable, std::string& errors) {
    SourceManager sources;
    DiagnosticEngine diags(sources);
    CompileOptions options;
    options.pipeline.pass.relaxed = relaxed;
    options.pipeline.pass.reloadable = reloadable;
    auto module = compileText("case.psys", text, sources, diags, options);
    if (!module) errors = diags.render(false);
    return module;
}

std::shared_ptr<rt::Backend> makeBackend(const Config& c, std::string& error) {
    if (c.backend == "interp") return std::make_shared<interp::Interpreter>();
    if (c.backend == "llvm")
        return std::make_shared<codegen_llvm::LlvmBackend>(c.exact ? codegen_llvm::MathMode::Exact : codegen_llvm::MathMode::Fast);
    std::shared_ptr<gpu::GlslBackend> gpu = gpu::GlslBackend::create(error);
    if (gpu && c.hostSide) gpu->setHostSide(std::make_unique<interp::Interpreter>(gpu->memory()));
    return gpu;
}

bool bitwiseEqual(const rt::RenderPoint& a, const rt::RenderPoint& b) {
    auto same = [](const auto& x, const auto& y) { return std::memcmp(&x, &y, sizeof x) == 0; };
    if (!(same(a.position, b.position) && same(a.color, b.color) && same(a.size, b.size) && same(a.rotation, b.rotation) &&
          same(a.frame, b.frame) && same(a.end, b.end) && a.trail.size() == b.trail.size()))
        return false;
    for (size_t i = 0; i < a.trail.size(); ++i)
        if (!same(a.trail[i], b.trail[i])) return false;
    return true;
}

// The largest difference of two points' values relative to max(1, |value|); a NaN on one
// side only is 1e9.
double difference(const rt::RenderPoint& a, const rt::RenderPoint& b) {
    double worst = 0;
    auto compare = [&worst](float x, float y) {
        double d = std::fabs(double(x) - double(y)) / std::max(1.0, std::fabs(double(x)));
        worst = std::max(worst, std::isnan(d) ? (std::isnan(x) && std::isnan(y) ? 0.0 : 1e9) : d);
    };
    for (size_t i = 0; i < 3; ++i) compare(a.position[i], b.position[i]);
    for (size_t i = 0; i < 4; ++i) compare(a.color[i], b.color[i]);
    compare(a.size, b.size);
    compare(a.rotation, b.rotation);
    compare(a.frame, b.frame);
    for (size_t i = 0; i < 3; ++i) compare(a.end[i], b.end[i]);
    for (size_t i = 0; i < std::min(a.trail.size(), b.trail.size()); ++i)
        for (size_t k = 0; k < 3; ++k) compare(a.trail[i][k], b.trail[i][k]);
    return worst;
}

class Run {
public:
    Run(const Case& c, const RunOptions& options) : c_(c), options_(options) {}

    std::optional<Finding> go() {
        for (const Config& config : options_.configs) {
            if (config.backend == "llvm" && !config.exact && !options_.compareFast) continue;
            Side side{config, nullptr, nullptr, {}};
            std::string error;
            side.backend = makeBackend(config, error);
            if (!side.backend) return Finding{config.label, "error", -1, "the backend cannot start: " + error};
            auto module = compile(c_.source, config.backend == "llvm" && !config.exact, !c_.edit.empty(), error);
            if (!module) return Finding{config.label, "compile", -1, error};
            if (module->instanced() && rt::System::checkBackend(*module, *side.backend))
                continue;  // (the glsl backend plays no instances yet)
            if (config.rowsInMemory && c_.paces()) continue;  // (instance speeds need the rows on the host)
            rt::SystemOptions systemOptions;
            if (config.rowsInMemory) {  // (drawn after the step, as the GPU draws: a type drawn as the
                systemOptions.rows = rt::SystemOptions::Rows::InMemory;  // step goes keeps its rows on the host)
                systemOptions.drawInStep = false;
            }
            side.system = std::make_unique<rt::System>(std::move(*module), *side.backend, systemOptions);
            if (config.threads) side.system->setThreads(config.threads);
            sides_.push_back(std::move(side));
        }
        if (sides_.size() < 2) return std::nullopt;
        folds_ = std::any_of(sides_[0].system->module().objects.begin(), sides_[0].system->module().objects.end(),
                             [](const ir::Object& o) { return !o.folds.empty(); });
        size_t next = 0;
        for (int f = 0; f < c_.frames; ++f) {
            for (; next < c_.events.size() && c_.events[next].frame <= f; ++next)
                if (auto found = event(c_.events[next], f)) return found;
            if (auto found = each(f, "step", [&](rt::System& s) { return s.step(c_.stepAt(f)); })) return found;
            if (auto found = compareDrawn(f)) return found;
            if (auto found = compareEvents(f)) return found;
            if ((f + 1) % kRowsEvery == 0 || f + 1 == c_.frames)
                if (auto found = compareRows(f)) return found;
        }
        return std::nullopt;
    }

private:
    const Case& c_;
    const RunOptions& options_;
    std::vector<Side> sides_;
    bool folds_ = false;

    template <typename F>
    std::optional<Finding> each(int f, const char* what, F&& fn) {
        std::optional<std::string> reference = fn(*sides_[0].system);
        for (size_t i = 1; i < sides_.size(); ++i) {
            std::optional<std::string> other = fn(*sides_[i].system);
            if (other.has_value() != reference.has_value())
                return Finding{sides_[i].config.label, "error", f,
                               fmt::format("{}: the interpreter says `{}`, this backend `{}`", what, reference.value_or("ok"),
                                           other.value_or("ok"))};
        }
        return std::nullopt;
    }

    std::optional<Finding> event(const Event& e, int f) {
        switch (e.kind) {
            case Event::Kind::Fire:
                return each(f, "fire", [&](rt::System& s) { return s.fire(e.name, e.values); });
            case Event::Kind::Set:
                return each(f, "set", [&](rt::System& s) { return s.setExtern(e.name, e.values); });
            case Event::Kind::Play: {
                std::array<float, 16> m = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, e.values.at(0), e.values.at(1), e.values.at(2), 1};
                if (auto found = each(f, "play", [&](rt::System& s) {
                        rt::InstanceHandle h = 0;
                        auto error = s.play(m, h);
                        for (Side& side : sides_)
                            if (side.system.get() == &s && !error) side.played.push_back(h);
                        return error;
                    }))
                    return found;
                for (size_t i = 1; i < sides_.size(); ++i)
                    if (sides_[i].played != sides_[0].played)
                        return Finding{sides_[i].config.label, "instances", f, "a play's handle is not the interpreter's"};
                return std::nullopt;
            }
            case Event::Kind::Stop: case Event::Kind::Kill: {
                auto k = static_cast<size_t>(e.values.at(0));
                if (k >= sides_[0].played.size()) return std::nullopt;  // (not played yet: a shrunk case)
                size_t side = 0;
                return each(f, e.kind == Event::Kind::Stop ? "stop" : "kill", [&](rt::System& s) {
                    rt::InstanceHandle h = sides_[side++].played[k];
                    return e.kind == Event::Kind::Stop ? s.stop(h) : s.kill(h);
                });
            }
            case Event::Kind::Speed: case Event::Kind::Pause: {
                auto k = static_cast<size_t>(e.values.at(0));
                if (k >= sides_[0].played.size()) return std::nullopt;  // (not played yet: a shrunk case)
                size_t side = 0;
                return each(f, e.kind == Event::Kind::Speed ? "speed" : "pause", [&](rt::System& s) {
                    rt::InstanceHandle h = sides_[side++].played[k];
                    return e.kind == Event::Kind::Speed ? s.setSpeed(h, e.values.at(1)) : s.pause(h, e.values.at(1) != 0);
                });
            }
            case Event::Kind::Reload:
                for (Side& side : sides_) {
                    std::string error;
                    auto module = compile(c_.edit, side.config.backend == "llvm" && !side.config.exact, true, error);
                    if (!module) return Finding{side.config.label, "compile", f, "the edit: " + error};
                    auto next = std::make_unique<rt::System>(std::move(*module), *side.backend, side.system->options());
                    next->carryOver(*side.system);
                    side.system = std::move(next);
                }
                return std::nullopt;
        }
        return std::nullopt;
    }

    std::optional<Finding> compareDrawn(int f) {
        rt::System& a = *sides_[0].system;
        for (size_t t = 0; t < a.typeCount(); ++t) {
            std::vector<rt::RenderPoint> pa = a.points(t);
            for (size_t i = 1; i < sides_.size(); ++i) {
                const Side& side = sides_[i];
                std::vector<rt::RenderPoint> pb = side.system->points(t);
                const std::string& type = a.module().objects[t].name;
                if (pa.size() != pb.size())
                    return Finding{side.config.label, "ids", f,
                                   fmt::format("`{}`: {} drawn, the interpreter draws {}", type, pb.size(), pa.size())};
                for (size_t k = 0; k < pa.size(); ++k) {
                    if (pa[k].id != pb[k].id)
                        return Finding{side.config.label, "ids", f,
                                       fmt::format("`{}`: point {} is object {}, the interpreter's {}", type, k, pb[k].id, pa[k].id)};
                    if (side.config.bitwise()) {
                        if (!bitwiseEqual(pa[k], pb[k]))
                            return Finding{side.config.label, "values", f,
                                           fmt::format("`{}` object {}: not the interpreter's bits (off by {:.3g})", type,
                                                       pa[k].id, difference(pa[k], pb[k]))};
                    } else if (!folds_ || f < kCrowdFrames) {
                        double d = difference(pa[k], pb[k]);
                        if (d > options_.tolerance)
                            return Finding{side.config.label, "values", f,
                                           fmt::format("`{}` object {}: off by {:.3g} (tolerance {})", type, pa[k].id, d,
                                                       options_.tolerance)};
                    }
                }
            }
        }
        return std::nullopt;
    }

    // The step's notifications, name by name, in the same order with the same values; the
    // instances that finished in it.
    std::optional<Finding> compareEvents(int f) {
        rt::System& a = *sides_[0].system;
        std::vector<float> va, vb;
        size_t wa = 0, wb = 0;
        for (const std::string& name : a.eventNames()) {
            if (auto error = a.events(name, va, wa)) return Finding{sides_[0].config.label, "error", f, *error};
            for (size_t i = 1; i < sides_.size(); ++i) {
                const Side& side = sides_[i];
                if (auto error = side.system->events(name, vb, wb)) return Finding{side.config.label, "error", f, *error};
                if (va.size() != vb.size() || wa != wb)
                    return Finding{side.config.label, "events", f,
                                   fmt::format("`{}`: {} notified, the interpreter {}", name, wb ? vb.size() / wb : 0,
                                               wa ? va.size() / wa : 0)};
                for (size_t k = 0; k < va.size(); ++k) {
                    bool same = side.config.bitwise() ? std::memcmp(&va[k], &vb[k], sizeof(float)) == 0
                                                      : std::fabs(double(va[k]) - double(vb[k])) /
                                                                std::max(1.0, std::fabs(double(va[k]))) <=
                                                            options_.tolerance;
                    if (!same && (side.config.bitwise() || !folds_ || f < kCrowdFrames))
                        return Finding{side.config.label, "events", f,
                                       fmt::format("`{}`: value {} is {}, the interpreter's {}", name, k, vb[k], va[k])};
                }
            }
        }
        std::span<const rt::InstanceHandle> done = a.finishedInstances();
        for (size_t i = 1; i < sides_.size(); ++i) {
            std::span<const rt::InstanceHandle> other = sides_[i].system->finishedInstances();
            if (!std::equal(done.begin(), done.end(), other.begin(), other.end()))
                return Finding{sides_[i].config.label, "instances", f,
                               fmt::format("{} instances finished, the interpreter's {}", other.size(), done.size())};
        }
        return std::nullopt;
    }

    std::optional<Finding> compareRows(int f) {
        for (Side& side : sides_) side.system->finish();
        const rt::System& a = *sides_[0].system;
        rt::Stats sa = a.stats();
        for (size_t i = 1; i < sides_.size(); ++i) {
            const rt::System& b = *sides_[i].system;
            const std::string& label = sides_[i].config.label;
            rt::Stats sb = b.stats();
            for (size_t t = 0; t < a.typeCount(); ++t) {
                const rt::Pool &pa = a.pool(t), &pb = b.pool(t);
                const std::string& type = a.module().objects[t].name;
                if (pa.rows() != pb.rows() || pa.generations() != pb.generations() || pa.freeRows() != pb.freeRows())
                    return Finding{label, "rows", f,
                                   fmt::format("`{}`: {} rows, {} free (the interpreter: {}, {})", type, pb.rows(),
                                               pb.freeRows().size(), pa.rows(), pa.freeRows().size())};
                for (uint32_t r = 0; r < pa.rows(); ++r)
                    if (pa.status(r) != pb.status(r))
                        return Finding{label, "rows", f, fmt::format("`{}`: row {} has another status", type, r)};
                const rt::TypeStats &x = sa.types[t], &y = sb.types[t];
                if (x.created != y.created || x.killed != y.killed || x.dropped != y.dropped || x.live != y.live ||
                    x.frozen != y.frozen || x.unstable != y.unstable)
                    return Finding{label, "counts", f,
                                   fmt::format("`{}`: created {} killed {} dropped {} live {} frozen {} (the interpreter: "
                                               "{} {} {} {} {})",
                                               type, y.created, y.killed, y.dropped, y.live, y.frozen, x.created, x.killed,
                                               x.dropped, x.live, x.frozen)};
            }
            if (sa.invalidEmissions != sb.invalidEmissions || sa.nonFiniteRender != sb.nonFiniteRender)
                return Finding{label, "counts", f, "invalid emissions or non-finite draws"};
        }
        return std::nullopt;
    }
};

}  // namespace

std::optional<Config> configNamed(const std::string& name) {
    for (const Config& c : allConfigs())
        if (c.label == name) return c;
    return std::nullopt;
}

std::vector<std::string> configNames() {
    std::vector<std::string> out;
    for (const Config& c : allConfigs()) out.push_back(c.label);
    return out;
}

std::string Finding::summary() const {
    return frame >= 0 ? fmt::format("{} {} at frame {}: {}", config, kind, frame, detail)
                      : fmt::format("{} {}: {}", config, kind, detail);
}

std::optional<Finding> runCase(const Case& c, const RunOptions& options) { return Run(c, options).go(); }

}  // namespace psys::progen
