// Helpers for the tests that run systems (unit and LLVM tests): compile a text to a
// module, and run a system recording what it draws.
#pragma once

#include <doctest/doctest.h>

#include <functional>
#include <optional>
#include <string>
#include <vector>

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

// A drawn point as bytes: its values, then a trail's points.
inline void appendPoint(std::string& out, const rt::RenderPoint& p) {
    auto bytes = [&out](const void* at, size_t n) { out.append(static_cast<const char*>(at), n); };
    bytes(&p.id, sizeof p.id);
    bytes(p.position.data(), sizeof p.position);
    bytes(p.color.data(), sizeof p.color);
    bytes(&p.size, sizeof p.size);
    bytes(&p.rotation, sizeof p.rotation);
    bytes(&p.frame, sizeof p.frame);
    bytes(p.end.data(), sizeof p.end);
    for (const auto& q : p.trail) bytes(q.data(), sizeof q);
}

// Everything drawn after each of `frames` steps of 1/60 s, as bytes.
inline std::string drawnBytes(rt::System& system, int frames) {
    std::string out;
    for (int f = 0; f < frames; ++f) {
        REQUIRE_FALSE(system.step(1.0 / 60));
        for (size_t t = 0; t < system.typeCount(); ++t)
            for (const rt::RenderPoint& p : system.points(t)) appendPoint(out, p);
    }
    return out;
}

// Where a system keeps its objects, as text: per type the high-water row, the free rows
// in order, and each row's status, generation and (not free) id. Two runs that free and
// reuse rows alike give the same text.
inline std::string poolRows(const rt::System& system) {
    std::string out;
    for (size_t t = 0; t < system.typeCount(); ++t) {
        const rt::Pool& pool = system.pool(t);
        const auto* ids = rt::viewData<uint32_t>(system.backend().memory(), pool.ids);
        out += "type " + std::to_string(t) + ": rows " + std::to_string(pool.rows()) + ", free";
        for (uint32_t row : pool.freeRows()) out += " " + std::to_string(row);
        out += "\n";
        for (uint32_t row = 0; row < pool.rows(); ++row) {
            out += " " + std::to_string(static_cast<int>(pool.status(row))) + "/" + std::to_string(pool.generations()[row]);
            if (pool.status(row) != rt::Status::Free) out += "#" + std::to_string(ids[row]);
        }
        out += "\n";
    }
    return out;
}

// What a host sees over `frames` steps of `text`, drawn on the frames `drawOn` picks,
// with the system's `drawInStep` option as given: every point drawn (as bytes), the drawn
// counts and the non-finite counter; on frame 20 an extern (the first) is set, on frame 40
// every trigger is fired. Two runs that differ only in drawInStep must give the same bytes.
inline std::string hostSees(const std::string& text, rt::Backend& backend, bool drawInStep, int frames,
                            const std::function<bool(int)>& drawOn) {
    rt::SystemOptions options;
    options.drawInStep = drawInStep;
    rt::System system(compileModule(text), backend, options);
    std::string out;
    for (int f = 0; f < frames; ++f) {
        if (f == 20 && !system.module().externs.empty()) {
            const ir::Extern& e = system.module().externs[0];
            std::vector<float> v(static_cast<size_t>(e.type.width));
            for (int c = 0; c < e.type.width; ++c) v[static_cast<size_t>(c)] = e.defaultValue[static_cast<size_t>(c)] * 0.5f + 0.25f;
            (void)system.setExtern(0, v);  // may be out of its range: then refused alike
        }
        if (f == 40)
            for (const ir::Trigger& t : system.module().triggers) {
                size_t width = 0;
                for (auto& p : t.params) width += static_cast<size_t>(p.type.width);
                REQUIRE_FALSE(system.fire(t.name, std::vector<float>(width, 1.5f)));
            }
        REQUIRE_FALSE(system.step(1.0 / 60));
        if (!drawOn(f)) continue;
        for (size_t t = 0; t < system.typeCount(); ++t) {
            size_t drawn = system.draw(t).drawn;
            out.append(reinterpret_cast<const char*>(&drawn), sizeof drawn);
            for (const rt::RenderPoint& p : system.points(t)) appendPoint(out, p);
        }
        uint64_t nonFinite = system.stats().nonFiniteRender;
        out.append(reinterpret_cast<const char*>(&nonFinite), sizeof nonFinite);
    }
    return out;
}

}  // namespace psys::test
