// `psysc run`: compile a system and step it through time (through the host library).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/integrators.h"

namespace psys::tools {

struct RunOptions {
    std::string file;
    int frames = 600;
    std::string dt = "1/60";
    uint32_t seed = 1;
    size_t capacity = 1 << 20;
    std::vector<std::string> sets;   // NAME=V[,V…]
    std::vector<std::string> fires;  // TRIGGER[:V,…]@FRAME
    std::string dump;                // FILE.csv or FILE.json
    int dumpEvery = 1;
    bool quiet = false;
    bool events = false;             // print each frame's notifications (rt::System::events)
    bool untilFinished = false;      // stop after the frame that leaves nothing alive (rt::System::finished)
    bool optimize = true;
    bool relaxed = false;
    std::optional<core::Integrator> integrator;  // every object's, whatever @integrator says
    double tolerance = 0;            // for objects without @tolerance; 0: none
    std::string backend = "llvm";    // host/backends.h
    std::string math = "fast";       // or "exact" (llvm)
    unsigned threads = 0;            // 0: every core
    std::string rows = "backend";    // rt::SystemOptions::Rows: backend, memory or host
    bool timing = false;
    bool remarks = false;
    bool printSchedule = false;
    bool colour = false;
};

// Returns the process exit status: 0, 1 (errors in the program), 2 (bad options).
int runSystem(const RunOptions& options);

}  // namespace psys::tools
