// Helpers for the tests that run systems (unit and LLVM tests): compile a text to a
// module, and run a system recording what it draws.
#pragma once

#include <doctest/doctest.h>

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "driver/compile.h"
#include "interp/interpreter.h"
#include "rt/system.h"
#include "tests/run_length.h"

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

// How many frames a sweep of `text` over many variants (every integration method, with
// and without the optimizer) runs, at most `limit`: until every object type that comes
// alive within `limit` frames (every trigger fired first, as the sweeps fire them) has been
// alive for `settle` of them — its creation, its first updates, what it emits — under each
// variant. Where a method could differ later, the variants differ in the update, which
// every frame runs; the long runs are the default method's (600 frames: run_length.h).
inline int coverFrames(const std::string& text, int limit, int settle = 30) {
    // (asked again for each variant of a sweep: worked out once)
    static std::map<std::tuple<std::string, int, int>, int> known;
    auto key = std::make_tuple(text, limit, settle);
    if (auto it = known.find(key); it != known.end()) return it->second;
    interp::Interpreter backend;
    rt::System system(compileModule(text), backend);
    for (const ir::Trigger& t : system.module().triggers) {
        size_t width = 0;
        for (auto& p : t.params) width += static_cast<size_t>(p.type.width);
        REQUIRE_FALSE(system.fire(t.name, std::vector<float>(width, 1.5f)));
    }
    std::vector<bool> seen(system.typeCount(), false), died(system.typeCount(), false);
    int need = settle;
    for (int f = 0; f < limit; ++f) {
        REQUIRE_FALSE(system.step(1.0 / 60));
        rt::Stats stats = system.stats();
        for (size_t t = 0; t < seen.size(); ++t) {
            if (!seen[t] && stats.types[t].live > 0) {
                seen[t] = true;
                need = std::max(need, f + 1 + settle);
            }
            if (!died[t] && stats.types[t].killed > 0) {  // and its first deaths
                died[t] = true;
                need = std::max(need, f + 1 + settle / 3);
            }
        }
    }
    return known[key] = std::min(limit, need);
}

// How many frames a sweep over every sample runs: the long run in the release build
// (run_length.h); under the sanitizers, which look for memory errors and undefined
// behaviour along the paths a run takes rather than for what a long run adds up, as many
// as coverFrames says each type needs — its creation, its updates, its first deaths — at
// most the sanitized long run (200).
inline int sweepFrames(const std::string& text) {
    return kSanitized ? std::min(longRun(), coverFrames(text, kLongRun)) : longRun();
}

}  // namespace psys::test
