// The pipeline: every pass in order, as one readable table (thesis §4.3.1). With
// --print-after the IR is logged after the named passes; in debug builds (and with
// verifyEach) the verifier checks the IR after every pass.
#include <ostream>

#include <fmt/format.h>

#include "ir/printer.h"
#include "ir/verifier.h"
#include "opt/passes.h"

namespace psys::opt {

// The pipeline, in order. Lowering first: cycles resolved, parent references scoped,
// then (optimising) the behaviour simplified while it is still one expression a value,
// temporal operators lowered to state, random draws keyed, the behaviour split into
// kernels; then the optimizer on the kernels.
const std::vector<PassInfo>& passes() {
    static const std::vector<PassInfo> all = {
        {"resolve-cycles", "recursive references become the previous update's value; a cycle through no integrate, prev or -> is an algebraic loop (thesis §3.1.5, §4.3.3–4.3.4)",
         PassRuns::Always, [](ir::Module& m, const PassOptions& o, PassErrors& e) { resolveCycles(m, o, e); }},
        {"scoping", "a child's `rocket.pos` becomes a value the parent exports once an update, read through the child's parent handle (thesis §4.3.5)",
         PassRuns::Always, [](ir::Module& m, const PassOptions&, PassErrors& e) { scoping(m, e); }},
        {"simplify", "constant folding and exact identities to a fixpoint, on the behaviour; a snapshot of what is fixed at creation needs no state",
         PassRuns::Optimizing, [](ir::Module& m, const PassOptions& o, PassErrors& e) { simplify(m, o, e); }},
        {"lower-temporal", "integrate, derive, prev, snapshot and -> become state slots, reads and next values, an object's integrals lowered together by its integration method (thesis §4.3.6, §3.3.7)",
         PassRuns::Always, [](ir::Module& m, const PassOptions& o, PassErrors& e) { lowerTemporal(m, o, e); }},
        {"key-random", "every random draw is keyed by (object id, draw index): the same seed gives the same particles on every backend (thesis §3.1.4)",
         PassRuns::Always, [](ir::Module& m, const PassOptions&, PassErrors& e) { keyRandom(m, e); }},
        {"split-kernels", "the behaviour becomes the kernels init, update, render, exports and spawn.N; what a post-update kernel needs from before the update is carried in state (thesis §3.3.1)",
         PassRuns::Always, [](ir::Module& m, const PassOptions&, PassErrors& e) { splitKernels(m, e); }},
        {"double-precision", "an object under @precision(double) keeps its state as pairs of floats (48 bits) and computes what writes it in pair arithmetic, the same bits on every backend",
         PassRuns::Always, [](ir::Module& m, const PassOptions&, PassErrors& e) { doublePrecision(m, e); }},
        {"reassociate", "sums and products in one canonical order, so (a+b+c)·(a+b+d) computes a+b once",
         PassRuns::Relaxed, [](ir::Module& m, const PassOptions&, PassErrors& e) { reassociate(m, e); }},
        {"simplify-kernels", "simplify again, on the split kernels",
         PassRuns::Optimizing, [](ir::Module& m, const PassOptions& o, PassErrors& e) { simplify(m, o, e); }},
        {"recompute-state", "a slot whose next value the next step can compute from the other slots and the clock is not stored",
         PassRuns::Relaxed, [](ir::Module& m, const PassOptions& o, PassErrors& e) { if (!o.reloadable) recomputeState(m, e); }},
        {"dead-state", "slots nothing needs go, equal slots merge, unchanged slots are not stored, parameters read only at creation are not kept",
         PassRuns::Optimizing, [](ir::Module& m, const PassOptions& o, PassErrors& e) { deadState(m, o, e); }},
        {"hoist-uniform", "what is the same for every object of a type (constants, dt, time, externs) is computed once a step in a uniform kernel",
         PassRuns::Optimizing, [](ir::Module& m, const PassOptions&, PassErrors& e) { hoistUniform(m, e); }},
        {"lower-storage", "what the run-time stores for each kernel beyond the declared columns (shared emission values, render columns drawn from state or constants, parent reads) recorded on the kernel",
         PassRuns::Always, [](ir::Module& m, const PassOptions&, PassErrors& e) { lowerStorage(m, e); }},
    };
    return all;
}

std::string passTable() {
    std::string out = "| pass | runs | what it does |\n|---|---|---|\n";
    for (const PassInfo& pass : passes()) {
        const char* runs = pass.runs == PassRuns::Always       ? "always"
                           : pass.runs == PassRuns::Optimizing ? "optimising"
                                                               : "optimising, relaxed maths";
        out += fmt::format("| {} | {} | {} |\n", pass.name, runs, pass.summary);
    }
    return out;
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
    for (const PassInfo& pass : passes()) {
        bool runs = pass.runs == PassRuns::Always || (options.optimize && (pass.runs == PassRuns::Optimizing ||
                                                                           options.pass.relaxed));
        if (!runs) continue;
        pass.run(module, options.pass, errors);
        if (!after(pass.name)) return false;
    }
    return true;
}

}  // namespace psys::opt
