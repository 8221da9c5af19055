#include "effects.h"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iostream>

#include "driver/compile.h"
#include "rt/system.h"

namespace psys::bench {

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0 : v[v.size() / 2];
}

const std::vector<Effect> kEffects = {
    {"fountain", "population", "drop", 200},
    {"fire", "rate", "part", 900},  // (its first particles fall back below the ground at about 12 s)
    {"fireworks", "sparks", "spark", 420},
};

const Effect* findEffect(const std::string& name) {
    auto e = std::find_if(kEffects.begin(), kEffects.end(), [&](const Effect& e) { return e.name == name; });
    return e == kEffects.end() ? nullptr : &*e;
}

std::string samplesDir() {
    const char* dir = std::getenv("PSYS_SAMPLES_DIR");
    return dir && *dir ? dir : PSYS_SAMPLES_DIR;
}

ir::Module compileEffect(const std::string& name, bool relaxed) {
    SourceManager sources;
    DiagnosticEngine diags(sources);
    CompileOptions options;
    options.pipeline.pass.relaxed = relaxed;
    auto module = compileFile(samplesDir() + "/" + name + ".psys", sources, diags, options);
    if (!module) {
        diags.print(std::cerr, false);
        std::exit(1);
    }
    // The fireworks as the thesis has them, and as bench/hand_written.cpp writes them:
    // rockets and their trails, no bursts of stars.
    for (ir::Extern& x : module->externs)
        if (name == "fireworks" && x.name == "stars") x.defaultValue = {0, 0, 0, 0};
    return std::move(*module);
}

double calibrate(const Effect& e, rt::Backend& backend, double particles) {
    if (e.name == "fountain") return particles;
    double probe = e.name == "fire" ? 2000 : 200;
    rt::System system(compileEffect(e.name), backend);
    float value = static_cast<float>(probe);
    system.setExtern(e.knob, {&value, 1});
    for (int f = 0; f < e.warmFrames; ++f) system.step(1.0 / 60);
    double live = static_cast<double>(system.pool(static_cast<size_t>(system.typeIndex(e.particles))).live());
    return probe * particles / std::max(live, 1.0);
}

double stateBytes(const ir::Object& o) {
    double bytes = 0;
    for (const auto& s : o.state) bytes += 2 * 4 * s.type.width;
    for (const auto& p : o.params)
        if (p.kept) bytes += 4 * p.type.width;
    return bytes;
}

bool writeJson(const std::string& path, const std::string& rows, const char* program) {
    std::ofstream out(path);
    out << rows << "\n";
    if (out) return true;
    std::cerr << program << ": cannot write " << path << "\n";
    return false;
}

}  // namespace psys::bench
