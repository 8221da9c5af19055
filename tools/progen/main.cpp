// psys-progen: generated programs run on every backend against the interpreter
// (tools/progen/generator.h, runner.h). Each case runs in a child process (a crash is a
// finding); a failing case is shrunk and written to --out.
//
//   psys-progen --seeds 1:200                  cases 1 to 200
//   psys-progen --minutes 30 --out DIR         as many cases as fit, from --first (default 1)
//   psys-progen --print 17                     the case of seed 17, as a file
//   psys-progen --replay FILE… [--out DIR]     kept cases (tests/programs/generated/); with
//                                              --out, one that fails is shrunk and kept there
//   --configs interp,llvm-exact-1t,…          the backends (the interpreter always first)
//
// The GL is the process's: PSYS_GPU_STRICT=1 for strict mode, GALLIUM_DRIVER=zink
// LIBGL_ALWAYS_SOFTWARE=1 for zink (docs/gpu.md). Exit 0 when nothing was found, 1 when
// something was, 2 on bad usage.
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "tools/progen/generator.h"
#include "tools/progen/isolate.h"

using namespace psys::progen;

namespace {

struct Tally {
    int cases = 0, compared = 0, fastCompared = 0, reloads = 0, found = 0;
    std::map<std::string, int> kinds;
};

double secondsSince(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// One case: run, and where something is found, attributed, shrunk and kept.
bool check(const Case& c, RunOptions options, const std::string& name, const std::string& out, unsigned timeout,
           int shrinkBudget, Tally& tally) {
    ++tally.cases;
    tally.fastCompared += options.compareFast;
    for (const Event& e : c.events) tally.reloads += e.kind == Event::Kind::Reload;
    auto found = runIsolated(c, options, timeout);
    if (!found) {
        ++tally.compared;
        return true;
    }
    if (found->kind == "crash" || found->kind == "timeout") *found = attributeCrash(c, options, *found, timeout);
    ++tally.found;
    ++tally.kinds[found->config + " " + found->kind];
    std::cout << fmt::format("{}: {}\n", name, found->summary()) << std::flush;
    if (!out.empty()) {
        writeCase(c, out, name + ".orig");
        Case small = shrinkBudget > 0 ? shrink(c, options, *found, timeout, shrinkBudget) : c;
        writeCase(small, out, name);
        std::cout << fmt::format("  kept {}/{}.psys ({} lines, from {})\n", out, name,
                                 std::count(small.source.begin(), small.source.end(), '\n'),
                                 std::count(c.source.begin(), c.source.end(), '\n'))
                  << std::flush;
    }
    return false;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"psys-progen: generated programs on every backend, against the interpreter"};
    std::string seeds, configs = "interp,llvm-exact-1t,llvm-exact-2t,llvm-fast-2t,glsl,glsl-device,interp-memory", out;
    double minutes = 0;
    uint64_t first = 1, print = 0;
    unsigned timeout = 120;
    int shrinkBudget = 300;
    double tolerance = 1e-3;
    std::vector<std::string> replay;
    bool quiet = false;
    app.add_option("--seeds", seeds, "A:B, the cases of seeds A to B");
    app.add_option("--minutes", minutes, "run cases from --first for this long");
    app.add_option("--first", first, "the first seed of --minutes");
    app.add_option("--print", print, "print the case of this seed and stop");
    app.add_option("--replay", replay, "run kept cases (NAME.psys, with NAME.edit.psys beside it)");
    app.add_option("--configs", configs, "the backends, comma-separated (" + fmt::format("{}", fmt::join(configNames(), ", ")) + ")");
    app.add_option("--out", out, "where a failing case is kept, shrunk (NAME.psys) and as found (NAME.orig.psys)");
    app.add_option("--timeout", timeout, "seconds a case may take");
    app.add_option("--shrink", shrinkBudget, "runs the shrinking of a failing case may take (0: none)");
    app.add_option("--tolerance", tolerance, "values of backends that round otherwise, relative to max(1, |v|)");
    app.add_flag("--quiet", quiet, "only findings and the summary");
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e) == 0 ? 0 : 2;
    }

    if (print) {
        Case c = generate(print);
        std::cout << caseText(c);
        if (!c.edit.empty()) std::cout << "// --- the edit (NAME.edit.psys) ---\n" << c.edit;
        return 0;
    }

    RunOptions options;
    options.tolerance = tolerance;
    std::string list = configs;
    size_t at = 0;
    options.configs.push_back(*configNamed("interp"));
    while (at <= list.size()) {
        size_t comma = list.find(',', at);
        std::string name = list.substr(at, comma == std::string::npos ? std::string::npos : comma - at);
        at = comma == std::string::npos ? list.size() + 1 : comma + 1;
        if (name.empty() || name == "interp") continue;
        auto c = configNamed(name);
        if (!c) {
            std::cerr << fmt::format("psys-progen: no backend `{}` (the backends are {})\n", name, fmt::join(configNames(), ", "));
            return 2;
        }
        options.configs.push_back(*c);
    }

    Tally tally;
    auto start = std::chrono::steady_clock::now();
    bool clean = true;
    if (!replay.empty()) {
        for (const std::string& path : replay) {
            std::string error;
            auto c = readCase(path, error);
            if (!c) {
                std::cerr << fmt::format("psys-progen: {}: {}\n", path, error);
                return 2;
            }
            RunOptions o = options;
            o.compareFast = c->compareFast;
            // With --out, a case that fails is shrunk and kept there under its own name.
            std::string name = std::filesystem::path(path).stem().string();
            bool ok = check(*c, o, out.empty() ? path : name, out, timeout, shrinkBudget, tally);
            if (ok && !quiet) std::cout << path << ": same on every backend\n";
            clean &= ok;
        }
    } else {
        uint64_t last = first;
        if (!seeds.empty()) {
            auto colon = seeds.find(':');
            try {
                first = std::stoull(seeds.substr(0, colon));
                last = colon == std::string::npos ? first : std::stoull(seeds.substr(colon + 1));
            } catch (const std::exception&) {
                std::cerr << "psys-progen: --seeds takes A:B\n";
                return 2;
            }
        } else if (minutes <= 0) {
            std::cerr << "psys-progen: --seeds, --minutes, --print or --replay\n";
            return 2;
        }
        for (uint64_t seed = first; seeds.empty() ? secondsSince(start) < minutes * 60 : seed <= last; ++seed) {
            Case c = generate(seed);
            RunOptions o = options;
            o.compareFast = c.compareFast;
            bool ok = check(c, o, fmt::format("seed{}", seed), out, timeout, shrinkBudget, tally);
            if (ok && !quiet) std::cout << fmt::format("seed {}: same on every backend\n", seed) << std::flush;
            clean &= ok;
        }
    }
    std::cout << fmt::format("{} cases in {:.0f} s ({} with fast maths compared, {} hot reloads): {} the same on every "
                             "backend, {} with a finding\n",
                             tally.cases, secondsSince(start), tally.fastCompared, tally.reloads, tally.compared, tally.found);
    for (const auto& [kind, n] : tally.kinds) std::cout << fmt::format("  {}: {}\n", kind, n);
    return clean ? 0 : 1;
}
