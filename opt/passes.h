// The catalogue of IR passes, in pipeline order. Each lives in its own file, whose header
// says why it exists; pipeline.cpp runs them in this order (thesis §4.3.1).
//
//   resolve-cycles   recursive references (`recur`) become the previous update's value;
//                    a cycle through no integrate/prev/-> is an algebraic loop (§3.1.5,
//                    §4.3.3–4.3.4)
//   scoping          a child's `rocket.pos` becomes a value the parent exports once per
//                    update; the child reads it through its parent handle (§4.3.5)
//   lower-temporal   integrate, derive, prev, snapshot and `->` become state slots,
//                    reads and next values (§4.3.6, §3.3.7); an object's integrals are
//                    lowered together by its integration method
//   key-random       every random draw is keyed by (object id, draw index) so that the
//                    same seed gives the same particles on every backend (§3.1.4)
//   split-kernels    the behaviour becomes the kernels init, update, render, exports and
//                    spawn.N; what the post-update kernels need from before the update is
//                    carried in state (§3.3.1: split stateful from stateless)
//
// and, unless optimisation is off, the optimizer (§4.3.8, docs/optimizer.md):
//
//   simplify         constant folding and exact identities to a fixpoint; snapshot of
//                    what is fixed at creation needs no state (runs on the behaviour,
//                    before lower-temporal, and as simplify-kernels after the split)
//   reassociate      (relaxed only) sums and products in one canonical order, so
//                    (a+b+c)·(a+b+d) computes a+b once
//   recompute-state  (relaxed only) a slot whose next value the next step can compute
//                    from the other slots and the clock (the fire's previous `acc`) is
//                    not stored
//   dead-state       slots nothing needs go, equal slots merge, unchanged slots are not
//                    stored, parameters read only at creation are not kept
//   hoist-uniform    what is the same for every object of a type (constants, dt, time,
//                    externs) is computed once per step in a uniform kernel
#pragma once

#include <iosfwd>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "ir/ir.h"
#include "ir/printer.h"

namespace psys::opt {

struct PassOptions {
    // The method for objects without @integrator.
    ir::Integrator integrator = ir::Integrator::SemiImplicit;
    // A method for every object, whatever its @integrator says (`psysc --integrator`:
    // trying a method without editing the source).
    std::optional<ir::Integrator> everyObject;
    // Rewrites that may change the last bits of a result (docs/optimizer.md): x+0 → x,
    // x/c → x·(1/c), sums and products put in one canonical order so they share parts,
    // and integrals of what is fixed at creation in closed form (c·age).
    bool relaxed = false;
};

// The integration method of an object under these options.
ir::Integrator methodOf(const ir::Object& object, const PassOptions& options);

// What a pass reports about the program, at the instruction (or object) it concerns.
struct PassMessage {
    ir::Loc loc;
    std::string text;
    bool warning = false;
};

class PassErrors {
public:
    void error(ir::Loc loc, std::string text) { all_.push_back({loc, std::move(text), false}); }
    void warning(ir::Loc loc, std::string text) { all_.push_back({loc, std::move(text), true}); }
    bool hasErrors() const {
        for (const PassMessage& m : all_)
            if (!m.warning) return true;
        return false;
    }
    bool empty() const { return all_.empty(); }
    size_t size() const { return all_.size(); }
    const PassMessage& operator[](size_t i) const { return all_[i]; }
    auto begin() const { return all_.begin(); }
    auto end() const { return all_.end(); }

private:
    std::vector<PassMessage> all_;
};

void resolveCycles(ir::Module& module, const PassOptions& options, PassErrors& errors);
void scoping(ir::Module& module, PassErrors& errors);
void lowerTemporal(ir::Module& module, const PassOptions& options, PassErrors& errors);
void keyRandom(ir::Module& module, PassErrors& errors);
void splitKernels(ir::Module& module, PassErrors& errors);
void simplify(ir::Module& module, const PassOptions& options, PassErrors& errors);
void reassociate(ir::Module& module, PassErrors& errors);
void hoistUniform(ir::Module& module, PassErrors& errors);
void recomputeState(ir::Module& module, PassErrors& errors);
void deadState(ir::Module& module, PassErrors& errors);

struct PassInfo {
    const char* name;
    const char* summary;
};
// The catalogue above, for --print-after and --help.
const std::vector<PassInfo>& passCatalogue();

struct PipelineOptions {
    PassOptions pass;
    bool optimize = true;              // false: only the lowering passes
    std::set<std::string> printAfter;  // pass names
    bool printAfterAll = false;
    bool verifyEach = false;           // run the verifier after every pass
    std::ostream* log = nullptr;       // where --print-after goes
    ir::PrintOptions print;            // how it is printed there (with locations or not)
};

// Runs every pass in order. Returns false (with `errors`) when the program is wrong or a
// pass broke an invariant (the verifier's message names the pass).
bool runPipeline(ir::Module& module, const PipelineOptions& options, PassErrors& errors);

}  // namespace psys::opt
