// The chooser behind `@tolerance(metres[, seconds])`: for each object that states a
// tolerance (or under a default one: `psysc --tolerance`), the cheapest integration method
// and sub-step whose drawn position stays within it.
//
// Why by trial: the error of a method depends on the derivatives' derivatives along the
// path an object takes, on its step and on float's rounding, none of which the compiler
// can bound from the equations alone (a spring's error grows with the number of periods;
// an orbit's with its phase). So each candidate — every method the object can use, at 1,
// 2, 4, 8 and 16 sub-steps a frame — is compiled and run on a small population (the
// system as written, at most `population` objects of each type alive), and its points
// compared, object by object and frame by frame, with a reference: the closed form where
// `exact` has one (its own error a few of float's steps at the largest coordinate), else
// rk4 with its state in double (@precision(double)) at the sub-step where it agrees best
// with itself at twice that step (their distance is the reference's own error, `floor`).
// A candidate meets the tolerance when its distance from the reference plus that floor is
// within it. Every method is also a candidate in double, for the tolerances float state's
// rounding cannot hold (a long orbit to 1e-4 m); its pair arithmetic makes it dearer, so
// float wins wherever it meets the tolerance. Candidates are tried cheapest first (a
// pass's arithmetic or, where more, its memory traffic, times the sub-steps:
// tolerance.cpp's passCost) and the first that meets the tolerance wins; a run stops as
// soon as it misses. Deterministic: the same source gives the same choice. Bounded: a
// program's trials run at most `budget` steps, whatever the horizons.
#pragma once

#include <atomic>
#include <optional>
#include <string>
#include <vector>

#include "core/integrators.h"
#include "ir/ir.h"
#include "opt/passes.h"
#include "rt/backend.h"

namespace psys::tune {

struct TuneOptions {
    double frame = 1.0 / 60;  // the host's step the choice is made for
    double tolerance = 0;     // for objects without @tolerance (psysc --tolerance); 0: none
    double horizon = core::kToleranceSeconds;  // seconds compared under a @tolerance that states no time
    size_t population = 64;   // objects of each type alive at once in a trial
    opt::PipelineOptions pipeline;  // the passes the trials are compiled with
    // The most steps (a frame's sub-steps of the trial population) the program's trials
    // may run, the references' included: the cost of the choices is bounded whatever the
    // horizon and however many objects state a tolerance (a @tolerance over 1000 s ran 12
    // million, a minute on the JIT). Past it an object keeps its integrator and step, with
    // a warning saying so.
    long budget = 2'000'000;
    // Set from another thread (an editor's newer text): the trials stop, nothing is chosen.
    const std::atomic<bool>* cancelled = nullptr;
};

struct Trial {
    core::Integrator method;
    int subSteps = 1;
    core::Precision precision = core::Precision::Float;
    double cost = 0;               // of an object's updates a frame, in adds on a lane (passCost)
    std::optional<double> error;   // distance from the reference; none: not run
};

struct Choice {
    std::string object;
    ir::Loc loc;
    double tolerance = 0, over = 0;  // metres, seconds compared
    double frame = 1.0 / 60;         // the host's step it was chosen for
    bool own = true;                 // its own @tolerance, else the default
    bool methodFixed = false;        // @integrator (or --integrator) given: only the sub-step chosen
    bool met = false;
    core::Integrator method = core::Integrator::SemiImplicit;
    int subSteps = 1;
    core::Precision precision = core::Precision::Float;
    bool precisionFixed = false;     // @precision(double) written: only candidates in double
    double error = 0;  // the chosen candidate's distance from the reference plus the floor
    double cost = 0;
    double floor = 0;       // the reference's own error estimate
    std::string reference;  // what the reference was
    double largest = 0;     // the largest coordinate the reference (rk4 in double) draws
    bool trusted = true;    // false: its own error is over 1% of that — it has not settled
    long steps = 0;         // run by this object's trials, the reference's included
    bool exhausted = false; // the budget ran out (or the trials were cancelled) before a choice
    std::vector<Trial> trials;  // cheapest first
};

// Chooses for each object of `module` (lowered, before the passes) that has a tolerance,
// and writes the choice into its attributes (integrator, step); a tolerance it cannot meet
// is a warning in `messages` with the best it found. `backend` runs the trials.
std::vector<Choice> chooseMethods(ir::Module& module, rt::Backend& backend, const TuneOptions& options,
                                  opt::PassErrors& messages);

// What was chosen and why, a paragraph an object (psysc check --explain).
std::string explain(const std::vector<Choice>& choices);

// "rk4 with 4 sub-steps (@step(1/240))", "exact", "rk4 in double (@precision(double))".
std::string describe(core::Integrator method, int subSteps, double frame,
                     core::Precision precision = core::Precision::Float);

}  // namespace psys::tune
