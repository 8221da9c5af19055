// The IR passes. Each lives in its own file, whose header says why it exists; the
// registry (`passes()`, opt/pipeline.cpp) lists them in pipeline order (thesis §4.3.1)
// with a line each, and is the one list: runPipeline runs it, `--print-after` and
// `psysc --help` take their names from it, `psysc --list-passes` prints it, and
// docs/optimizer.md's table of passes is checked against it (tests/unit/passes_test.cpp).
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
    // The system may be hot-reloaded (the viewer, the C API, Python): its state must be
    // the program's own — every parameter kept, each integral a slot of its own from
    // zero — whatever the maths, since a reload carries state by name
    // (rt/reload.cpp). So, under relaxed maths too, no closed form c·age for an integral
    // (nothing would carry it), no integral that starts at c (it would carry c with it),
    // no slot recomputed instead of stored; and a parameter read only at creation is kept.
    bool reloadable = false;
};

// The integration method of an object under these options.
ir::Integrator methodOf(const ir::Object& object, const PassOptions& options);

// What a pass reports about the program, at the instruction (or object) it concerns.
struct PassMessage {
    ir::Loc loc;
    std::string text;
    bool warning = false;
    // Attributes any of which would fix it on the object named (`@step(1/90)`): the
    // editor's quick fixes.
    std::string object;
    std::vector<std::string> attributes;
};

class PassErrors {
public:
    void error(ir::Loc loc, std::string text) { all_.push_back({loc, std::move(text), false, {}, {}}); }
    void warning(ir::Loc loc, std::string text, std::string object = {}, std::vector<std::string> attributes = {}) {
        all_.push_back({loc, std::move(text), true, std::move(object), std::move(attributes)});
    }
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
void doublePrecision(ir::Module& module, PassErrors& errors);
// Whether double-precision computes `op` in pairs (where its operands are floats): simplify
// does not fold it on constants in the behaviour of an object in double, so that the pass
// pairs it with the optimizer as without it.
bool pairedOp(ir::Op op);
void simplify(ir::Module& module, const PassOptions& options, PassErrors& errors);
void reassociate(ir::Module& module, PassErrors& errors);
void hoistUniform(ir::Module& module, PassErrors& errors);
void recomputeState(ir::Module& module, PassErrors& errors);
void deadState(ir::Module& module, const PassOptions& options, PassErrors& errors);
void lowerStorage(ir::Module& module, PassErrors& errors);
// Not a pass: where a large argument meets sin, cos or tan, which fast maths may round
// differently (opt/large_arguments.cpp); for `psysc check --remarks`.
std::vector<PassMessage> largeArgumentRemarks(const ir::Module& module);

// When a pass runs: always (the lowering to kernels), when optimising, or when optimising
// with relaxed maths (PassOptions::relaxed).
enum class PassRuns : uint8_t { Always, Optimizing, Relaxed };

struct PassInfo {
    const char* name;     // as --print-after takes it
    const char* summary;  // what it does, one line
    PassRuns runs;
    void (*run)(ir::Module& module, const PassOptions& options, PassErrors& errors);
};
// Every pass, in the order the pipeline runs them.
const std::vector<PassInfo>& passes();
// The registry as docs/optimizer.md shows it (and `psysc --list-passes` prints): a
// Markdown table, a row a pass.
std::string passTable();

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
