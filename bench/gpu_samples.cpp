#include "gpu_samples.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "driver/compile.h"
#include "effects.h"
#include "rt/system.h"

namespace psys::bench {

void startTimes(ir::Module& module, size_t copies) {
    ir::Kernel& start = module.start.kernel;
    for (ir::Yield& y : start.yields)
        if (y.kind == ir::YieldKind::EmitCount) y.value = start.scalar(static_cast<float>(copies));
}

namespace {

std::string readFileText(const std::string& path) {
    std::ifstream in(path);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct SampleRun {
    size_t copies = 1;
    double live = 0;  // every type's, averaged over the measured steps
    double dispatches = 0, bytes = 0, waits = 0, lateReads = 0;  // per step
    std::vector<std::string> hostRows;  // the types whose rows the host keeps
};

std::optional<SampleRun> runSample(gpu::GlslBackend& gpu, const std::string& path, const std::string& text,
                                   size_t copies, double size, const SampleScale& scale) {
    SourceManager sources;
    DiagnosticEngine diags(sources);
    auto module = compileText(path, text, sources, diags);
    if (!module) {
        diags.print(std::cerr, false);
        return std::nullopt;
    }
    startTimes(*module, copies);
    rt::SystemOptions options;
    options.capacity = std::max(options.capacity, static_cast<size_t>(size * 2));
    options.rows = scale.rows;
    rt::System system(std::move(*module), gpu, options);
    auto live = [&] {
        double n = 0;
        for (size_t t = 0; t < system.typeCount(); ++t) n += static_cast<double>(system.pool(t).live());
        return n;
    };
    for (double t = 0; t < scale.warmSeconds; t += 1.0 / 20)
        if (auto error = system.step(1.0 / 20)) {
            std::cerr << path << ": " << *error << "\n";
            return std::nullopt;
        }
    SampleRun r;
    r.copies = copies;
    uint64_t dispatches = gpu.dispatches(), bytes = gpu.transferredBytes(), waits = gpu.waits(), late = gpu.lateReads();
    for (int f = 0; f < scale.frames; ++f) {
        system.step(1.0 / 60);
        r.live += live();
    }
    double frames = scale.frames;
    r.live /= frames;
    r.dispatches = static_cast<double>(gpu.dispatches() - dispatches) / frames;
    r.bytes = static_cast<double>(gpu.transferredBytes() - bytes) / frames;
    r.waits = static_cast<double>(gpu.waits() - waits) / frames;
    r.lateReads = static_cast<double>(gpu.lateReads() - late) / frames;
    for (size_t t = 0; t < system.typeCount(); ++t)
        if (!system.pool(t).rowsInMemory()) r.hostRows.push_back(system.module().objects[t].name);
    return r;
}

std::vector<std::string> sampleNames(const SampleScale& scale) {
    if (!scale.only.empty()) return scale.only;
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(samplesDir()))
        if (entry.path().extension() == ".psys") names.push_back(entry.path().stem().string());
    std::sort(names.begin(), names.end());
    return names;
}

}  // namespace

int sampleFigures(std::ostream& out, gpu::GlslBackend& gpu, const SampleScale& scale, const std::string& json) {
    for (const std::string& name : sampleNames(scale))
        if (!std::filesystem::is_regular_file(samplesDir() + "/" + name + ".psys")) {
            std::cerr << "psys_gpu_bench: there is no sample `" << name << "` (" << samplesDir() << "/" << name
                      << ".psys); --only takes names separated by spaces\n";
            return 2;
        }
    out << "\n| sample | spawns × | live | dispatches/step | host↔GPU bytes/step | waits/step | late reads/step | rows on the host |\n"
           "|---|---:|---:|---:|---:|---:|---:|---|\n";
    nlohmann::json rows = nlohmann::json::array();
    int status = 0;
    for (const std::string& name : sampleNames(scale)) {
        std::string path = samplesDir() + "/" + name + ".psys";
        std::string text = readFileText(path);
        std::optional<SampleRun> probe = runSample(gpu, path, text, 1, 0, scale);
        if (!probe) {
            status = 1;
            continue;
        }
        for (double size : scale.sizes) {
            auto copies = static_cast<size_t>(std::max(1.0, std::round(size / std::max(probe->live, 1.0))));
            std::optional<SampleRun> r = runSample(gpu, path, text, copies, size, scale);
            if (!r) {
                status = 1;
                break;
            }
            std::string host;
            for (const std::string& t : r->hostRows) host += (host.empty() ? "" : ", ") + t;
            out << fmt::format("| {} | {} | {:.3g} | {:.1f} | {:.0f} | {:.1f} | {:.1f} | {} |\n", name, r->copies, r->live,
                               r->dispatches, r->bytes, r->waits, r->lateReads, host.empty() ? "—" : host);
            out.flush();
            rows.push_back({{"sample", name}, {"copies", r->copies}, {"live", r->live}, {"dispatches", r->dispatches},
                            {"bytes", r->bytes}, {"waits", r->waits}, {"late_reads", r->lateReads},
                            {"host_rows", r->hostRows}});
        }
    }
    if (!json.empty() && !writeJson(json, rows.dump(2), "psys_gpu_bench")) return 1;
    out << "\n(spawns ×: the sample's `spawn`s started that many times; live: every type's objects, averaged over the "
           "measured steps; dispatches, bytes and waits per step of 1/60 s after a warm-up; rows on the host: the types "
           "whose pools keep their rows on the host, whose bookkeeping grows with them)\n";
    return status;
}

}  // namespace psys::bench
