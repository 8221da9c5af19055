// The pipeline: every pass in order, as one readable function (thesis §4.3.1). With
// --print-after the IR is logged after the named passes; in debug builds (and with
// verifyEach) the verifier checks the IR after every pass.
#include <ostream>

#include <fmt/format.h>

#include "ir/printer.h"
#include "ir/verifier.h"
#include "opt/passes.h"

namespace psys::opt {

const std::vector<PassInfo>& passCatalogue() {
    static const std::vector<PassInfo> passes = {
        {"resolve-cycles", "recursive references become the previous update's value"},
        {"scoping", "parent references become values the parent exports"},
        {"lower-temporal", "integrate, derive, prev, snapshot and -> become state"},
        {"key-random", "random draws are keyed by (object id, draw index)"},
        {"split-kernels", "the behaviour becomes init, update, render, exports and spawn kernels"},
        {"simplify", "constant folding and exact identities (on the behaviour)"},
        {"simplify-kernels", "constant folding and exact identities (on the split kernels)"},
        {"reassociate", "(relaxed) sums and products in one canonical order, sharing common parts"},
        {"recompute-state", "(relaxed) a slot the next step can compute from the other slots and the clock is not stored"},
        {"dead-state", "unneeded slots go, equal slots merge, parameters used only at creation are not kept"},
    };
    return passes;
}

bool runPipeline(ir::Module& module, const PipelineOptions& options, PassErrors& errors) {
#ifndef NDEBUG
    const bool verifyEach = true;
#else
    const bool verifyEach = options.verifyEach;
#endif
    auto after = [&](const char* pass) {
        if (errors.hasErrors()) return false;
        if (options.log && (options.printAfterAll || options.printAfter.count(pass)))
            *options.log << "; IR after " << pass << "\n" << ir::print(module, options.print);
        if (verifyEach) {
            for (const std::string& problem : ir::verify(module))
                errors.error({}, fmt::format("internal error: the IR after {} is malformed: {}", pass, problem));
        }
        return !errors.hasErrors();
    };
    if (verifyEach)
        for (const std::string& problem : ir::verify(module))
            errors.error({}, "internal error: the lowered IR is malformed: " + problem);
    if (errors.hasErrors()) return false;

    resolveCycles(module, options.pass, errors);
    if (!after("resolve-cycles")) return false;
    scoping(module, errors);
    if (!after("scoping")) return false;
    if (options.optimize) {
        simplify(module, options.pass, errors);
        if (!after("simplify")) return false;
    }
    lowerTemporal(module, options.pass, errors);
    if (!after("lower-temporal")) return false;
    keyRandom(module, errors);
    if (!after("key-random")) return false;
    splitKernels(module, errors);
    if (!after("split-kernels")) return false;
    if (!options.optimize) return true;
    if (options.pass.relaxed) {
        reassociate(module, errors);
        if (!after("reassociate")) return false;
    }
    simplify(module, options.pass, errors);
    if (!after("simplify-kernels")) return false;
    if (options.pass.relaxed) {
        recomputeState(module, errors);
        if (!after("recompute-state")) return false;
    }
    deadState(module, errors);
    if (!after("dead-state")) return false;
    hoistUniform(module, errors);
    return after("hoist-uniform");
}

}  // namespace psys::opt
