#include "neighbours.h"

#include <cmath>
#include <numbers>
#include <vector>

#include <fmt/format.h>

#include "effects.h"
#include "driver/compile.h"
#include "gpu/glsl_backend.h"
#include "rt/system.h"

namespace psys::bench {

double crowdSide(double n, double neighbours) {
    return std::cbrt(n * (4.0 / 3.0) * std::numbers::pi / neighbours);  // a unit ball holds `neighbours`
}

ir::Module crowdModule(double n, double neighbours) {
    std::string text = fmt::format(R"(
        @capacity({0})
        object grain(ipos: vec3) {{
            push = near_sum(grain, 1, (pos - other.pos) * (1 - distance(pos, other.pos)));
            crowd = near_count(grain, 1);
            vel = vec3(0) -> prev(vel) * 0.99 + push * dt;
            pos = ipos -> prev(pos) + vel * dt;
            point(pos, vec4(crowd / 40, 0, 0, 1), 1);
        }}
        object source {{ emit grain(rand3() * {1}) count {0}; kill when age > 0; }}
        spawn source;)",
                                   static_cast<size_t>(n), crowdSide(n, neighbours));
    CompileOptions options;
    options.pipeline.pass.relaxed = true;  // as the JIT's fast maths compiles
    SourceManager sources;
    DiagnosticEngine diags(sources);
    auto module = compileText("crowd.psys", text, sources, diags, options);
    if (!module) throw std::runtime_error("the crowd does not compile:\n" + diags.render());
    return std::move(*module);
}

FoldFigures measureCrowd(rt::Backend& backend, double n, double neighbours, int frames, unsigned threads) {
    rt::SystemOptions options;
    options.threads = threads;
    options.capacity = static_cast<size_t>(n) + 16;
    rt::System system(crowdModule(n, neighbours), backend, options);
    for (int f = 0; f < 3; ++f) system.step(1.0 / 60);
    std::vector<double> steps, folds;
    auto type = static_cast<size_t>(system.typeIndex("grain"));
    FoldFigures out;
    for (int f = 0; f < frames; ++f) {
        double before = system.stats().foldSeconds;
        auto start = Clock::now();
        system.step(1.0 / 60);
        system.finish();  // (a device: the step done)
        steps.push_back(seconds(start, Clock::now()));
        folds.push_back(system.stats().foldSeconds - before);
        out.live += static_cast<double>(system.pool(type).live());
    }
    out.live /= frames;
    out.stepSeconds = median(steps);
    out.foldSeconds = median(folds);
    out.pairs = out.live * neighbours;  // (the expected count: the hand-written grid counts its own)
    return out;
}

int crowdFigures(std::ostream& out, gpu::GlslBackend& gpu, const std::vector<double>& sizes, int frames) {
    out << fmt::format("# neighbour folds on {}: a crowd, about 32 within reach of each, median of {} steps\n\n",
                       gpu.report().target, frames);
    out << "| particles | step ms (host) | passes on the GPU a step (ms) | fold ns per particle | M pairs/s | waits/step | "
           "host↔GPU KB/step |\n|---:|---:|---|---:|---:|---:|---:|\n";
    for (double n : sizes) {
        FoldFigures f = measureCrowd(gpu, n, 32, frames);
        // Again, its passes timed (timer queries), and what a step waits for and moves once
        // the crowd is made (the first step sends every particle up).
        rt::SystemOptions options;
        options.capacity = static_cast<size_t>(n) + 16;
        rt::System system(crowdModule(n, 32), gpu, options);
        for (int k = 0; k < 3; ++k) system.step(1.0 / 60);
        system.finish();
        uint64_t waits = gpu.waits(), moved = gpu.transferredBytes();
        auto before = gpu.passTimes();
        gpu.timePasses(true);
        for (int k = 0; k < frames; ++k) system.step(1.0 / 60);
        system.finish();
        gpu.timePasses(false);
        double waited = static_cast<double>(gpu.waits() - waits) / frames;
        double kb = static_cast<double>(gpu.transferredBytes() - moved) / frames / 1e3;
        double foldMs = 0;
        std::string passes;
        for (const auto& [pass, t] : gpu.passTimes()) {
            const auto* b = before.count(pass) ? &before.at(pass) : nullptr;
            double ms = (t.milliseconds - (b ? b->milliseconds : 0)) / frames;
            if (ms <= 0) ms = (t.wallMilliseconds - (b ? b->wallMilliseconds : 0)) / frames;
            passes += fmt::format("{}{} {:.2f}", passes.empty() ? "" : ", ", pass, ms);
            if (pass == "fold") foldMs = ms;
        }
        // (a device without timer queries or pass times, llvmpipe: no fold figures)
        bool timed = foldMs > 0;
        out << fmt::format("| {:.0e} | {:.2f} | {} | {} | {} | {:.1f} | {:.1f} |\n", n, f.stepSeconds * 1e3, passes,
                           timed ? fmt::format("{:.1f}", foldMs * 1e6 / f.live) : "—",
                           timed ? fmt::format("{:.0f}", f.pairs / (foldMs * 1e-3) / 1e6) : "—", waited, kb);
    }
    return 0;
}

}  // namespace psys::bench
