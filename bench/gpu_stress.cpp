#include "gpu_stress.h"

#include <iostream>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "driver/compile.h"
#include "effects.h"
#include "gpu_figures.h"
#include "interp/interpreter.h"
#include "rt/system.h"

namespace psys::bench {

namespace {

std::string chain(int capacity) {
    return fmt::format("@capacity({}) object a {{ emit a; point(vec3(age, 0, 0), white, 1); kill when age > 0.5; }}\n"
                       "spawn a;\n", capacity);
}

std::string types(int count) {
    std::string text;
    for (int t = 0; t < count; ++t)
        text += fmt::format("object t{0} {{ p = integrate(vec3({0}, 1, 0)); point(p, white, 1); }}\nspawn t{0};\n", t);
    return text;
}

// Seconds to make the system (compiling its kernels for the backend) and run `frames`
// frames of it, drawing each; a negative number where it would not compile or step.
double run(const std::string& text, rt::Backend& backend, int frames) {
    SourceManager sources;
    DiagnosticEngine diags(sources);
    auto module = compileText("stress.psys", text, sources, diags, {});
    if (!module) return -1;
    auto start = Clock::now();
    rt::System system(std::move(*module), backend);
    for (int f = 0; f < frames; ++f) {
        if (system.step(1.0 / 60)) return -1;
        for (size_t t = 0; t < system.typeCount(); ++t) system.draw(t);
    }
    system.finish();
    return seconds(start, Clock::now());
}

}  // namespace

int stressFigures(std::ostream& out, int frames) {
    struct Shape {
        std::string name, text;
    };
    const Shape shapes[] = {{"burst chain, @capacity(10000)", chain(10000)},
                            {"burst chain, @capacity(100000)", chain(100000)},
                            {"100 types of one object", types(100)},
                            {"400 types of one object", types(400)}};
    out << fmt::format("\n| shape ({} frames, drawn each) | GLSL backend (s) | interpreter (s) | GLSL ÷ interpreter |\n"
                       "|---|---:|---:|---:|\n", frames);
    for (const Shape& s : shapes) {
        auto gpu = gpuBackend("psys_gpu_bench");
        if (!gpu) return 1;
        interp::Interpreter interpreter;
        double g = run(s.text, *gpu, frames), i = run(s.text, interpreter, frames);
        if (g < 0 || i < 0) return 1;
        out << fmt::format("| {} | {:.2f} | {:.2f} | {:.1f} |\n", s.name, g, i, g / i);
        out.flush();
    }
    return 0;
}

}  // namespace psys::bench
