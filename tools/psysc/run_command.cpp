#include "run_command.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "driver/compile.h"
#include "codegen_llvm/llvm_backend.h"
#include "interp/interpreter.h"
#include "rt/system.h"

namespace psys::tools {
namespace {

// "0.5", "1/60", "1e-3"
std::optional<double> parseNumber(const std::string& text) {
    auto slash = text.find('/');
    char* end = nullptr;
    if (slash != std::string::npos) {
        auto a = parseNumber(text.substr(0, slash)), b = parseNumber(text.substr(slash + 1));
        if (!a || !b) return std::nullopt;
        return *a / *b;
    }
    double v = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0') return std::nullopt;
    return v;
}

std::optional<std::vector<float>> parseList(const std::string& text) {
    std::vector<float> out;
    if (text.empty()) return out;
    size_t start = 0;
    while (start <= text.size()) {
        size_t comma = text.find(',', start);
        std::string item = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
        auto v = parseNumber(item);
        if (!v) return std::nullopt;
        out.push_back(static_cast<float>(*v));
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    return out;
}

struct Fire {
    std::string trigger;
    std::vector<float> args;
    int frame;
};

class Dump {
public:
    explicit Dump(const std::string& path) : path_(path), json_(path.ends_with(".json")) {
        if (!path.empty() && !json_) {
            out_.open(path);
            out_ << "frame,time,type,id,x,y,z,r,g,b,a,size\n";
        }
    }
    bool ok() const { return path_.empty() || json_ || out_.good(); }

    void frame(int frame, rt::System& system) {
        if (path_.empty()) return;
        nlohmann::json objects = nlohmann::json::array();
        for (size_t t = 0; t < system.typeCount(); ++t) {
            const std::string& type = system.module().objects[t].name;
            for (const rt::RenderPoint& p : system.render(t)) {
                if (json_) {
                    objects.push_back({{"type", type},
                                       {"id", p.id},
                                       {"position", p.position},
                                       {"color", p.color},
                                       {"size", p.size}});
                } else {
                    out_ << fmt::format("{},{},{},{},{},{},{},{},{},{},{},{}\n", frame, system.time(), type, p.id,
                                        p.position[0], p.position[1], p.position[2], p.color[0], p.color[1],
                                        p.color[2], p.color[3], p.size);
                }
            }
        }
        if (json_) frames_.push_back({{"frame", frame}, {"time", system.time()}, {"objects", objects}});
    }

    bool finish() {
        if (path_.empty() || !json_) return ok();
        std::ofstream out(path_);
        out << nlohmann::json{{"frames", frames_}}.dump(1) << "\n";
        return out.good();
    }

private:
    std::string path_;
    bool json_;
    std::ofstream out_;
    nlohmann::json frames_ = nlohmann::json::array();
};

}  // namespace

int runSystem(const RunOptions& options) {
    auto dt = parseNumber(options.dt);
    if (!dt) {
        std::cerr << "psysc: error: --dt takes a number of seconds (such as 0.016 or 1/60), not `" << options.dt << "`\n";
        return 2;
    }
    std::vector<std::pair<std::string, std::vector<float>>> sets;
    for (const std::string& s : options.sets) {
        auto eq = s.find('=');
        auto values = eq == std::string::npos ? std::nullopt : parseList(s.substr(eq + 1));
        if (!values) {
            std::cerr << "psysc: error: --set takes NAME=VALUE or NAME=X,Y,Z, not `" << s << "`\n";
            return 2;
        }
        sets.push_back({s.substr(0, eq), *values});
    }
    std::vector<Fire> fires;
    for (const std::string& f : options.fires) {
        auto at = f.rfind('@');
        auto colon = f.find(':');
        double frame = -1;
        if (at != std::string::npos)
            if (auto n = parseNumber(f.substr(at + 1))) frame = *n;
        std::optional<std::vector<float>> args = std::vector<float>{};
        if (colon != std::string::npos && colon < at) args = parseList(f.substr(colon + 1, at - colon - 1));
        if (frame < 0 || !args) {
            std::cerr << "psysc: error: --fire takes TRIGGER@FRAME or TRIGGER:X,Y,Z@FRAME, not `" << f << "`\n";
            return 2;
        }
        fires.push_back({f.substr(0, std::min(colon, at)), *args, static_cast<int>(frame)});
    }

    SourceManager sources;
    DiagnosticEngine diags(sources);
    CompileOptions compile;
    compile.pipeline.optimize = options.optimize;
    compile.pipeline.pass.relaxed = options.relaxed;
    auto module = compileFile(options.file, sources, diags, compile);
    diags.print(std::cerr, options.colour);
    if (!module) return 1;

    std::unique_ptr<rt::Backend> backend;
    codegen_llvm::LlvmBackend* jit = nullptr;
    if (options.backend == "llvm") {
        auto llvm = std::make_unique<codegen_llvm::LlvmBackend>(options.math == "exact" ? codegen_llvm::MathMode::Exact
                                                                                       : codegen_llvm::MathMode::Fast);
        jit = llvm.get();
        backend = std::move(llvm);
    } else {
        backend = std::make_unique<interp::Interpreter>();
    }
    rt::SystemOptions systemOptions;
    systemOptions.seed = options.seed;
    systemOptions.capacity = options.capacity;
    systemOptions.threads = options.threads;
    rt::System system(std::move(*module), *backend, systemOptions);
    if (jit && options.remarks)
        for (const auto& r : jit->remarks())
            std::cout << fmt::format("{}: {}: {}\n", r.function, r.vectorized ? "vectorized" : "not vectorized", r.message);
    using Clock = std::chrono::steady_clock;
    double stepSeconds = 0, renderSeconds = 0;
    for (auto& [name, values] : sets)
        if (auto error = system.setExtern(name, values)) {
            std::cerr << "psysc: error: --set " << name << ": " << *error << "\n";
            return 2;
        }
    Dump dump(options.dump);
    if (!dump.ok()) {
        std::cerr << "psysc: error: cannot write `" << options.dump << "`\n";
        return 2;
    }
    for (int frame = 1; frame <= options.frames; ++frame) {
        for (const Fire& f : fires)
            if (f.frame == frame)
                if (auto error = system.fire(f.trigger, f.args)) {
                    std::cerr << "psysc: error: --fire " << f.trigger << ": " << *error << "\n";
                    return 2;
                }
        auto stepStart = Clock::now();
        if (auto error = system.step(*dt)) {
            std::cerr << "psysc: error: " << *error << "\n";
            return 2;
        }
        auto renderStart = Clock::now();
        stepSeconds += std::chrono::duration<double>(renderStart - stepStart).count();
        if (!options.quiet) {
            std::string line = fmt::format("frame {:4}  t={:.4f}", frame, system.time());
            rt::Stats stats = system.stats();
            for (auto& t : stats.types) line += fmt::format("  {} {}", t.name, t.live);
            std::cout << line << "\n";
        }
        // Every frame is drawn (as a host would), so points with NaN or infinite values
        // are counted even when nothing is dumped.
        for (size_t t = 0; t < system.typeCount(); ++t) system.render(t);
        renderSeconds += std::chrono::duration<double>(Clock::now() - renderStart).count();
        if (options.dumpEvery > 0 && frame % options.dumpEvery == 0) dump.frame(frame, system);
    }
    if (!dump.finish()) {
        std::cerr << "psysc: error: cannot write `" << options.dump << "`\n";
        return 2;
    }
    rt::Stats stats = system.stats();
    if (options.timing) {
        if (jit) {
            auto c = jit->compileStats();
            std::cout << fmt::format("compiled {} kernels in {:.1f} ms ({}, {} math)\n", c.kernels, c.seconds * 1e3,
                                     jit->cpu(), options.math);
        }
        int frames = std::max(options.frames, 1);
        std::cout << fmt::format("stepping {:.3f} ms per frame (update loops {:.3f}, kills and emissions {:.3f}, "
                                 "creation {:.3f}), drawing {:.3f} ms per frame\n",
                                 stepSeconds * 1e3 / frames, stats.loopSeconds * 1e3 / frames,
                                 stats.emitSeconds * 1e3 / frames, stats.createSeconds * 1e3 / frames,
                                 renderSeconds * 1e3 / frames);
    }
    std::cout << fmt::format("after {} frames ({:.3f} s):\n", options.frames, system.time());
    for (auto& t : stats.types)
        std::cout << fmt::format("  {:24} live {:8}  created {:10}  killed {:10}  frozen {:4}  dropped {}\n", t.name,
                                 t.live, t.created, t.killed, t.frozen, t.dropped);
    if (stats.rejectedSteps || stats.nonFiniteExterns || stats.invalidEmissions || stats.nonFiniteRender)
        std::cout << fmt::format("  rejected steps {}, non-finite extern values {}, invalid emissions {}, "
                                 "points not drawn (non-finite) {}\n",
                                 stats.rejectedSteps, stats.nonFiniteExterns, stats.invalidEmissions,
                                 stats.nonFiniteRender);
    return 0;
}

}  // namespace psys::tools
