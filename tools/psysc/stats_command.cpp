#include "stats_command.h"

#include <iostream>

#include <fmt/format.h>

#include "driver/compile.h"
#include "opt/stats.h"
#include "rt/pool.h"

namespace psys::tools {

namespace {

struct Compiled {
    std::optional<ir::Module> module;
    std::vector<opt::ObjectCost> costs;
};

Compiled compile(const std::string& file, const CompileOptions& options, bool print, bool colour) {
    SourceManager sources;
    DiagnosticEngine diags(sources);
    Compiled c;
    c.module = compileFile(file, sources, diags, options);
    if (print) diags.print(std::cerr, colour);
    if (c.module) c.costs = opt::measure(*c.module);
    return c;
}

std::string percent(size_t a, size_t b) { return b ? fmt::format("{:.0f}%", 100.0 * a / b) : std::string("-"); }

// Operations per update of every object under every method (optimized, exact maths): the
// cost of accuracy, next to docs/accuracy.md's error figures.
void printByMethod(const std::string& file, const std::vector<std::string>& objects,
                   const std::vector<std::string>& own) {
    std::cout << "\nops/update under each integration method (* the object's own):\n";
    std::string header = fmt::format("{:24}", "object");
    for (auto name : core::kIntegratorNames) header += fmt::format(" {:>14}", name);
    std::cout << header << "\n";
    std::vector<std::vector<std::string>> cells(objects.size());
    for (size_t m = 0; m < core::kIntegratorNames.size(); ++m) {
        CompileOptions options;
        options.pipeline.pass.everyObject = static_cast<core::Integrator>(m);
        Compiled c = compile(file, options, false, false);
        for (size_t i = 0; i < objects.size(); ++i) {
            std::string cell = c.module ? std::to_string(c.costs[i].opsPerUpdate) : "no closed form";
            if (own[i] == core::kIntegratorNames[m]) cell += "*";
            cells[i].push_back(cell);
        }
    }
    for (size_t i = 0; i < objects.size(); ++i) {
        std::string line = fmt::format("{:24}", objects[i]);
        for (const std::string& cell : cells[i]) line += fmt::format(" {:>14}", cell);
        std::cout << line << "\n";
    }
    std::cout << "(an object with no closed form for one of its integrals cannot use `exact`; a file where any "
                 "object has none reads `no closed form` in that column for every object)\n";
}

}  // namespace

int printStats(const std::string& file, std::optional<core::Integrator> everyObject, bool colour) {
    // Three compilations: no optimizer, the exact optimizer, and with relaxed maths.
    std::vector<Compiled> levels;
    for (int level = 0; level < 3; ++level) {
        CompileOptions options;
        options.pipeline.optimize = level > 0;
        options.pipeline.pass.relaxed = level == 2;
        options.pipeline.pass.everyObject = everyObject;
        levels.push_back(compile(file, options, level == 0, colour));
        if (!levels.back().module) return 1;
    }
    opt::PassOptions defaults;
    defaults.everyObject = everyObject;
    std::vector<std::string> objects, own;
    for (const ir::Object& o : levels[0].module->objects) {
        objects.push_back(o.name);
        own.emplace_back(core::integratorName(opt::methodOf(o, defaults)));
    }
    std::cout << fmt::format("{:24} {:>14} {:>10} {:>22} {:>6} {:>6} {:>24} {:>16} {:>14} {:>12}\n", "object", "method",
                             "tree ops", "ops/update", "exact", "relax", "state bytes/object", "param bytes",
                             "uniform ops", "row bytes");
    size_t total[3] = {0, 0, 0}, tree = 0;
    for (size_t i = 0; i < objects.size(); ++i) {
        const auto &b = levels[0].costs[i], &e = levels[1].costs[i], &r = levels[2].costs[i];
        tree += b.treeOpsPerUpdate;
        total[0] += b.opsPerUpdate;
        total[1] += e.opsPerUpdate;
        total[2] += r.opsPerUpdate;
        std::cout << fmt::format("{:24} {:>14} {:>10} {:>22} {:>6} {:>6} {:>24} {:>16} {:>14} {:>12}\n", b.name, own[i],
                                 b.treeOpsPerUpdate, fmt::format("{} / {} / {}", b.opsPerUpdate, e.opsPerUpdate, r.opsPerUpdate),
                                 percent(e.opsPerUpdate, b.opsPerUpdate), percent(r.opsPerUpdate, b.opsPerUpdate),
                                 fmt::format("{} / {} / {}", b.stateBytes, e.stateBytes, r.stateBytes),
                                 fmt::format("{} / {} / {}", b.paramBytes, e.paramBytes, r.paramBytes),
                                 fmt::format("{} / {} / {}", b.uniformOps, e.uniformOps, r.uniformOps),
                                 fmt::format("{} / {}", rt::Pool::rowBytes(levels[1].module->objects[i]),
                                             rt::Pool::rowBytes(levels[2].module->objects[i])));
    }
    std::cout << fmt::format("{:24} {:>14} {:>10} {:>22} {:>6} {:>6}\n", "all", "", tree,
                             fmt::format("{} / {} / {}", total[0], total[1], total[2]), percent(total[1], total[0]),
                             percent(total[2], total[0]));
    std::cout << fmt::format("optimized / tree ops: {} exact, {} relaxed\n", percent(total[1], tree), percent(total[2], tree));
    std::cout << "(ops/update: scalar operations per object per frame, without the optimizer / optimized / optimized "
                 "with --relaxed-math; tree ops: the same expressions evaluated as trees, nothing shared; uniform ops: "
                 "per type per step; row bytes: one object's row in its pool, optimized / with --relaxed-math (what the JIT "
                 "runs with fast maths) — kept state, kept parameters, exports, creation time, id, update and alive "
                 "masks and the run-time's bookkeeping)\n";
    printByMethod(file, objects, own);
    return 0;
}

}  // namespace psys::tools
