// Helpers for the tests that run systems (unit and LLVM tests): compile a text to a
// module, and run a system recording what it draws.
#pragma once

#include <doctest/doctest.h>

#include <optional>
#include <string>

#include "driver/compile.h"
#include "rt/system.h"

namespace psys::test {

// `diagnostics`, when given, receives what compiling printed (warnings).
inline ir::Module compileModule(const std::string& text, bool optimize = true,
                                std::optional<core::Integrator> integrator = {}, bool relaxed = false,
                                std::string* diagnostics = nullptr) {
    SourceManager sources;
    DiagnosticEngine diags(sources);
    CompileOptions options;
    options.pipeline.optimize = optimize;
    options.pipeline.pass.relaxed = relaxed;
    options.pipeline.pass.everyObject = integrator;
    auto module = compileText("test.psys", text, sources, diags, options);
    if (diagnostics) *diagnostics = diags.render();
    INFO(diags.render());
    REQUIRE(module.has_value());
    return std::move(*module);
}

// Everything drawn after each of `frames` steps of 1/60 s, as bytes.
inline std::string drawnBytes(rt::System& system, int frames) {
    std::string out;
    for (int f = 0; f < frames; ++f) {
        REQUIRE_FALSE(system.step(1.0 / 60));
        for (size_t t = 0; t < system.typeCount(); ++t)
            for (const rt::RenderPoint& p : system.points(t)) out.append(reinterpret_cast<const char*>(&p), sizeof p);
    }
    return out;
}

}  // namespace psys::test
