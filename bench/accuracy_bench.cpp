// accuracy_bench: the speed ↔ accuracy trade of the integration methods, measured
// (docs/accuracy.md is its output).
//
// Each reference problem in bench/accuracy/ has an exact solution. For every method and
// step (1/15 … 1/240 s, and frames of 1/60 s in @step(1/240) sub-steps) one object is
// stepped on the LLVM JIT (the default, fast maths) and compared with the solution after
// every step: the largest and the last error. The cost of an update is measured in the
// same run: the same problem with 100 000 copies, on one thread, ns per object update.
// A stiff decay is run at k·dt from 0.1 to 100 to see which methods stay bounded, and
// the fountain with integrals gives the cost of each method on a real effect. Last, what
// @tolerance chooses on each problem against the cheapest that meets it by brute force,
// and float state against @precision(double) (measured on the state, not the drawn floats).
//
//   psys_accuracy [--csv FILE] [--copies N] [--quick] [--tolerance-only [--explain]] [--precision-only]
//
// The CSV is what bench/plot_accuracy.py draws (docs/images/accuracy.png).
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <array>
#include <cmath>
#include <fstream>
#include <algorithm>
#include <functional>
#include <iostream>
#include <map>
#include <numbers>
#include <optional>

#include "codegen_llvm/llvm_backend.h"
#include "driver/compile.h"
#include "frontend/source.h"
#include "interp/interpreter.h"
#include "rt/system.h"
#include "tune/tolerance.h"

using namespace psys;
using core::Integrator;

namespace {

constexpr double kPi = std::numbers::pi;

// What a problem's error is measured on: the drawn point's position and colour, or the
// same values read from the state (in double, hi + lo, under @precision(double)).
struct Place {
    std::array<double, 3> position{};
    std::array<double, 4> color{};
};

Place placeOf(const rt::RenderPoint& p) {
    return {{p.position[0], p.position[1], p.position[2]}, {p.color[0], p.color[1], p.color[2], p.color[3]}};
}

struct Problem {
    std::string file, type;
    double seconds;
    // The error of a drawn point at time t against the exact solution.
    std::function<double(const Place&, double)> error;
    // The distance of the whole drawn point from its exact place, where the point draws
    // more than the position (the springs draw (x, v, 0)): what @tolerance bounds.
    std::function<double(const Place&, double)> drawn = nullptr;
    // Where the state keeps the drawn values (stateAccuracy): the slots of the integrals
    // the position and velocity are, each plus the constant it starts from in the source
    // (`pos = vec3(1, 0, 0) + integrate(vel)`). The springs draw (x, v, 0).
    std::string position = "integrate@pos", velocity = "integrate@vel";
    std::array<double, 3> positionFrom{}, velocityFrom{};
    bool springs = false;
};

// A number of a problem's source as the program has it: a float.
double f32(double x) { return static_cast<float>(x); }

// The time the updates have integrated to after `frames` steps of `frame` s: a kernel's dt
// is a float, so frames·float(frame). The clock, a double, says frames·frame, 5e-8 of it
// apart (1/60 as a float is 1/60·(1 + 5.2e-8)): below float state's rounding, but the
// largest error of a state in double measured against the clock (docs/accuracy.md).
double timeAfter(long frames, double frame) { return static_cast<double>(frames) * f32(frame); }

double norm3(double x, double y, double z) { return std::sqrt(x * x + y * y + z * z); }

// Position error of a point against an exact position.
double positionError(const Place& p, double x, double y, double z) {
    return norm3(p.position[0] - x, p.position[1] - y, p.position[2] - z);
}

// bench/accuracy/eccentric.psys: a = 0.625, e = 0.6, from the far end at t = 0. The mean
// anomaly M = π + n·t (n = a^−1.5), Kepler's equation E − e·sin E = M by Newton's method,
// then x = −a·(cos E − e), y = −b·sin E with b = a·√(1 − e²). The speed it starts at is
// √0.4 as a float, so a and e are those of that speed: a = 1/(2 − v²), e = 1/a − 1 (0.625
// and 0.6 to 1e-8).
const double kEccentricV = static_cast<float>(std::sqrt(0.4));
const double kEccentricA = 1 / (2 - kEccentricV * kEccentricV), kEccentricE = 1 / kEccentricA - 1;
const double kEccentricPeriod = 2 * kPi * std::pow(kEccentricA, 1.5);
std::pair<double, double> keplerPosition(double t) {
    const double a = kEccentricA, e = kEccentricE, b = a * std::sqrt(1 - e * e);
    double m = kPi + t * std::pow(a, -1.5), E = m;
    for (int i = 0; i < 50; ++i) {
        double dE = (E - e * std::sin(E) - m) / (1 - e * std::cos(E));
        E -= dE;
        if (std::fabs(dE) < 1e-15) break;
    }
    return {-a * (std::cos(E) - e), -b * std::sin(E)};
}

// The exact solutions are those of the problems as their programs state them: their
// numbers as floats (g = −9.8 is −9.80000019), the arithmetic on them exact (the springs'
// w·w): what a state in double is measured against.
std::vector<Problem> problems() {
    const double g = f32(-9.8), w = f32(6.2831853);
    // x'' = −k·x − c·x' from x = 1 at rest: x = e^(−a·t)·(cos(ωd·t) + a/ωd·sin(ωd·t)),
    // x' = −e^(−a·t)·(k/ωd)·sin(ωd·t), with a = c/2 and ωd = √(k − a²).
    auto spring = [](double k, double c) {
        const double a = c / 2, wd = std::sqrt(k - a * a);
        return [=](double t) {
            return std::array<double, 2>{std::exp(-a * t) * (std::cos(wd * t) + a / wd * std::sin(wd * t)),
                                         -std::exp(-a * t) * (k / wd) * std::sin(wd * t)};
        };
    };
    auto undamped = spring(w * w, 0), damped = spring(w * w, 2 * f32(0.1) * w);
    auto springProblem = [](const char* file, auto exact) {
        return Problem{file, "mass", 10, [=](const Place& p, double t) { return std::fabs(p.position[0] - exact(t)[0]); },
                       [=](const Place& p, double t) { return positionError(p, exact(t)[0], exact(t)[1], 0); },
                       "integrate@x", "integrate@v", {1, 0, 0}, {}, true};
    };
    Problem orbit{"orbit", "planet", 200 * kPi,  // 100 periods
                  [](const Place& p, double t) { return positionError(p, std::cos(t), std::sin(t), 0); }};
    orbit.positionFrom = {1, 0, 0};
    orbit.velocityFrom = {0, 1, 0};
    Problem eccentric{"eccentric", "planet", 2 * kEccentricPeriod, [](const Place& p, double t) {
                          auto [x, y] = keplerPosition(t);
                          return positionError(p, x, y, 0);
                      }};
    eccentric.positionFrom = {1, 0, 0};
    eccentric.velocityFrom = {0, kEccentricV, 0};
    Problem projectile{"projectile", "ball", 2,
                       [=](const Place& p, double t) { return positionError(p, 2 * t, 10 * t + g * t * t / 2, 0); }};
    projectile.velocityFrom = {2, 10, 0};
    Problem drag{"drag", "ball", 4, [=](const Place& p, double t) {
                     // vel = v∞ + (v0 − v∞)e^(−kt), pos = v∞·t + (v0 − v∞)(1 − e^(−kt))/k per component.
                     const double k = 0.5, decay = (1 - std::exp(-k * t)) / k;
                     double x = 2 * decay, y = (g / k) * t + (10 - g / k) * decay;
                     return positionError(p, x, y, 0);
                 }};
    drag.velocityFrom = {2, 10, 0};
    return {projectile, drag, springProblem("spring", undamped), springProblem("damped_spring", damped), orbit, eccentric};
}

// The orbit's energy v²/2 − 1/r (velocity in the colour), relative to its exact −1/2.
double energyDrift(const Place& p) {
    double v = norm3(p.color[0], p.color[1], p.color[2]);
    double r = norm3(p.position[0], p.position[1], p.position[2]);
    return std::fabs((v * v / 2 - 1 / r) + 0.5) / 0.5;
}

struct Step {
    std::string label;
    double frame;    // the host's step
    bool subSteps;   // the program says @step(1/240)
    double h() const { return subSteps ? 1.0 / 240 : frame; }
};

const std::vector<Step> kSteps = {{"1/15", 1.0 / 15, false},   {"1/30", 1.0 / 30, false},
                                  {"1/60", 1.0 / 60, false},   {"1/120", 1.0 / 120, false},
                                  {"1/240", 1.0 / 240, false}, {"1/60 @step(1/240)", 1.0 / 60, true}};

std::string readFile(const std::string& path) {
    std::ifstream in(path);
    if (!in) {
        std::cerr << "psys_accuracy: cannot read " << path << "\n";
        std::exit(1);
    }
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::optional<ir::Module> compile(const std::string& text, Integrator method) {
    SourceManager sources;
    DiagnosticEngine diags(sources);
    CompileOptions options;
    options.pipeline.pass.everyObject = method;
    return compileText("problem.psys", text, sources, diags, options);
}

struct Measured {
    bool closedForm = true;  // false: `exact` has none for this problem
    double maxError = 0, finalError = 0, drift = 0;
    double nsPerUpdate = 0;  // per object per frame
};

class Bench {
public:
    Bench(size_t copies, bool quick) : copies_(copies), quick_(quick) {}

    // Steps one object through the problem, comparing its drawn point after every step.
    Measured accuracy(const Problem& problem, const std::string& text, Integrator method, const Step& step) {
        return measure(problem, step.subSteps ? "@step(1/240);\n" + text : text, method, step,
                       [&](rt::System& system, size_t type) {
                           auto points = system.points(type);
                           if (points.size() != 1) {
                               std::cerr << "psys_accuracy: " << problem.file << " has " << points.size() << " objects\n";
                               std::exit(1);
                           }
                           return placeOf(points[0]);
                       });
    }

    // As accuracy(), on the state itself rather than the drawn floats: the problem's
    // position and velocity slots, hi + lo where the object keeps pairs (`pairs`: the
    // program under @precision(double)).
    Measured stateAccuracy(const Problem& problem, const std::string& text, Integrator method, const Step& step,
                           bool pairs) {
        std::string source = std::string(pairs ? "@precision(double);\n" : "") + (step.subSteps ? "@step(1/240);\n" : "") + text;
        return measure(problem, source, method, step, [&](rt::System& system, size_t type) {
            const ir::Object& object = system.pool(type).object();
            auto slot = [&](const std::string& name) {
                for (size_t i = 0; i < object.state.size(); ++i)
                    if (object.state[i].name == name) return static_cast<int>(i);
                return -1;
            };
            auto read = [&](const std::string& name, const std::array<double, 3>& from) {
                std::array<double, 3> out = from;
                int hi = slot(name), lo = slot(name + "@lo");
                if (hi < 0) {
                    std::cerr << "psys_accuracy: " << problem.file << " keeps no slot " << name << "\n";
                    std::exit(1);
                }
                ir::Value h = system.pool(type).state.get(system.backend().memory(), hi, 0);
                ir::Value l = lo >= 0 ? system.pool(type).state.get(system.backend().memory(), lo, 0) : ir::Value{};
                for (size_t i = 0; i < 3; ++i) out[i] += static_cast<double>(h.f[i]) + l.f[i];
                return out;
            };
            auto x = read(problem.position, problem.positionFrom), v = read(problem.velocity, problem.velocityFrom);
            Place p;
            if (problem.springs) {
                p.position = {x[0], v[0], 0};
            } else {
                p.position = x;
                p.color = {v[0], v[1], v[2], 1};
            }
            return p;
        });
    }

    // ns per object per frame: `copies` objects of the problem's type, on one thread.
    double cost(const std::string& text, const std::string& type, Integrator method, const Step& step) {
        std::string source = (step.subSteps ? "@step(1/240);\n" : "") + text +
                             fmt::format("\nobject copies {{ emit {} count {}; }}\nspawn copies;\n", type, copies_);
        auto module = compile(source, method);
        if (!module) return NAN;
        rt::SystemOptions options;
        options.threads = 1;
        options.capacity = copies_ + 16;
        rt::System system(std::move(*module), jit_, options);
        for (int f = 0; f < 3; ++f)
            if (system.step(step.frame)) std::exit(1);
        // The median of rounds: the machine drifts, and two methods that cost the same
        // should read the same.
        int frames = quick_ ? 3 : 10;
        std::vector<double> rounds;
        for (int r = 0; r < (quick_ ? 1 : 5); ++r) {
            double before = system.stats().loopSeconds;
            for (int f = 0; f < frames; ++f)
                if (system.step(step.frame)) std::exit(1);
            size_t live = system.stats().types[static_cast<size_t>(system.typeIndex(type))].live;
            rounds.push_back((system.stats().loopSeconds - before) * 1e9 / (static_cast<double>(live) * frames));
        }
        std::sort(rounds.begin(), rounds.end());
        return rounds[rounds.size() / 2];
    }

    codegen_llvm::LlvmBackend& jit() { return jit_; }

private:
    // One object of `source` stepped through the problem, where `where` says it is
    // compared with the exact solution after every step.
    Measured measure(const Problem& problem, const std::string& source, Integrator method, const Step& step,
                     const std::function<Place(rt::System&, size_t)>& where) {
        Measured m;
        auto module = compile(source, method);
        if (!module) {
            m.closedForm = false;
            return m;
        }
        rt::SystemOptions options;
        options.threads = 1;
        rt::System system(std::move(*module), jit_, options);
        double seconds = quick_ ? std::min(problem.seconds, 1.0) : problem.seconds;
        auto frames = static_cast<long>(std::lround(seconds / step.frame));
        size_t type = static_cast<size_t>(system.typeIndex(problem.type));
        Place last;
        for (long f = 1; f <= frames; ++f) {
            if (system.step(step.frame)) std::exit(1);
            last = where(system, type);
            double e = problem.error(last, timeAfter(f, step.frame));
            m.maxError = std::isfinite(e) ? std::max(m.maxError, e) : INFINITY;
            m.finalError = e;
        }
        if (problem.file == "orbit") m.drift = energyDrift(last);
        return m;
    }

    codegen_llvm::LlvmBackend jit_;
    size_t copies_;
    bool quick_;
};

std::vector<Integrator> methods() {
    std::vector<Integrator> all;
    for (size_t i = 0; i < core::kIntegratorNames.size(); ++i) all.push_back(static_cast<Integrator>(i));
    return all;
}

std::string sci(double x) {
    if (std::isnan(x)) return "—";
    if (std::isinf(x)) return "∞";
    return fmt::format("{:.1e}", x);
}

// The order of convergence between two step sizes, from the largest errors; none where
// the finer error is down at float's rounding (the state's own precision).
std::string order(double coarse, double fine) {
    if (!(coarse > 0) || !(fine > 2e-5) || !std::isfinite(coarse) || !std::isfinite(fine)) return "—";
    return fmt::format("{:.2f}", std::log2(coarse / fine));
}

void accuracyTables(Bench& bench, const std::string& dir, std::ofstream* csv) {
    for (const Problem& p : problems()) {
        std::string text = readFile(dir + "/" + p.file + ".psys");
        std::cout << fmt::format("\n### {} ({} s)\n\n", p.file, fmt::format("{:.4g}", p.seconds));
        std::cout << "| method | ns/update |";
        for (const Step& s : kSteps) std::cout << " " << s.label << " |";
        std::cout << " order (1/30→1/60→1/120) |" << (p.file == "orbit" ? " energy drift at 1/60 |" : "") << "\n|---|---|";
        for (size_t i = 0; i < kSteps.size() + 1 + (p.file == "orbit"); ++i) std::cout << "---|";
        std::cout << "\n";
        for (Integrator m : methods()) {
            std::string name(core::integratorName(m));
            double cost = bench.cost(text, p.type, m, kSteps[2]);
            double subCost = bench.cost(text, p.type, m, kSteps[5]);
            std::cout << "| " << name << " | " << (std::isnan(cost) ? "—" : fmt::format("{:.2f}", cost)) << " |";
            std::vector<Measured> row;
            for (const Step& s : kSteps) {
                Measured r = bench.accuracy(p, text, m, s);
                r.nsPerUpdate = s.subSteps ? subCost : cost;
                row.push_back(r);
                std::cout << " " << (r.closedForm ? fmt::format("{} / {}", sci(r.maxError), sci(r.finalError))
                                                  : std::string("no closed form"))
                          << " |";
                if (csv && r.closedForm)
                    *csv << fmt::format("{},{},{},{},{},{},{},{},{}\n", p.file, name, s.label, s.frame, s.h(),
                                        r.maxError, r.finalError, r.nsPerUpdate, r.drift);
            }
            std::cout << " " << order(row[1].maxError, row[2].maxError) << ", " << order(row[2].maxError, row[3].maxError)
                      << " |";
            if (p.file == "orbit") std::cout << " " << (row[2].closedForm ? sci(row[2].drift) : "—") << " |";
            std::cout << "\n";
        }
    }
    std::cout << "\n(max / final error against the exact solution: position, in metres; ns/update: one object's "
                 "update at 1/60 s on the JIT, one thread; the @step column costs four updates a frame)\n";
}

// rate·dt from 0.1 to 100 at 60 frames a second for one second.
void stiffTable(Bench& bench, const std::string& dir, std::ofstream* csv) {
    std::string text = readFile(dir + "/stiff.psys");
    const double dt = 1.0 / 60;
    std::cout << "\n### stiff decay v' = −k·v, 1 s at 60 frames a second\n\n| k·dt |";
    for (Integrator m : methods()) std::cout << " " << core::integratorName(m) << " |";
    std::cout << "\n|---|";
    for (size_t i = 0; i < methods().size(); ++i) std::cout << "---|";
    std::cout << "\n";
    for (double kdt : {0.1, 0.5, 1.0, 1.9, 2.5, 2.8, 3.0, 10.0, 100.0}) {
        std::cout << "| " << kdt << " |";
        for (Integrator m : methods()) {
            auto module = compile(text, m);
            rt::System system(std::move(*module), bench.jit());
            float rate[] = {static_cast<float>(kdt / dt)};
            if (system.setExtern("rate", rate)) std::exit(1);
            double worst = 0, last = 0;
            bool bounded = true, oscillates = false;
            float previous = 1;
            for (int f = 1; f <= 60; ++f) {
                if (system.step(dt)) std::exit(1);
                auto points = system.points(0);  // a non-finite point is not drawn
                float v = points.empty() ? INFINITY : points[0].position[0];
                worst = std::max(worst, std::fabs(v - std::exp(-kdt * f)));
                bounded &= std::fabs(v) <= 1;
                oscillates |= (v < 0) != (previous < 0);
                previous = v;
                last = v;
            }
            uint64_t unstable = system.stats().types[0].unstable;
            std::string outcome = !bounded ? "grows" : oscillates ? "oscillates" : "decays";
            std::cout << fmt::format(" {} {}{} |", outcome, sci(worst), unstable ? " ⚑" : "");
            if (csv)
                *csv << fmt::format("stiff,{},k·dt={},{},{},{},{},{},{}\n", core::integratorName(m), kdt, dt, dt,
                                    worst, last, 0, unstable);
        }
        std::cout << "\n";
    }
    std::cout << "\n(decays / oscillates / grows, then the largest error against e^(−k·t); ⚑: the run-time counted "
                 "its updates as beyond the method's stability limit)\n";
}

// The fountain with integrals: ns per drop update under each method, at 100 000 drops on
// one thread (the state stays in the caches: the arithmetic shows) and at a million on
// every core (memory-bound, as docs/performance.md's fountain).
void fountainTable(Bench& bench, const std::string& dir, bool quick) {
    std::string text = readFile(dir + "/fountain.psys");
    struct Setting {
        float population;
        unsigned threads;
    };
    const std::vector<Setting> settings = {{100000, 1}, {quick ? 100000.0f : 1000000.0f, 0}};
    std::cout << "\n### the fountain (bench/accuracy/fountain.psys)\n\n| method | 100 000 drops, one thread: ns per "
                 "drop update | relative to euler | 1 000 000 drops, every core: ns per drop update | relative to "
                 "euler |\n|---|---|---|---|---|\n";
    std::vector<double> euler(settings.size(), 0);
    for (Integrator m : methods()) {
        std::cout << "| " << core::integratorName(m) << " |";
        for (size_t s = 0; s < settings.size(); ++s) {
            auto module = compile(text, m);
            if (!module) {
                std::cout << " no closed form | — |";
                continue;
            }
            rt::SystemOptions options;
            options.threads = settings[s].threads;
            options.capacity = 1200000;
            rt::System system(std::move(*module), bench.jit(), options);
            float population[] = {settings[s].population};
            if (system.setExtern("population", population)) std::exit(1);
            for (int f = 0; f < 200; ++f)
                if (system.step(1.0 / 60)) std::exit(1);
            // Median of rounds of 20 frames: the machine drifts.
            std::vector<double> rounds;
            for (int r = 0; r < (quick ? 1 : 5); ++r) {
                double before = system.stats().loopSeconds;
                for (int f = 0; f < 20; ++f)
                    if (system.step(1.0 / 60)) std::exit(1);
                size_t live = system.stats().types[static_cast<size_t>(system.typeIndex("drop"))].live;
                rounds.push_back((system.stats().loopSeconds - before) * 1e9 / (static_cast<double>(live) * 20));
            }
            std::sort(rounds.begin(), rounds.end());
            double ns = rounds[rounds.size() / 2];
            if (m == Integrator::Euler) euler[s] = ns;
            std::cout << fmt::format(" {:.2f} | {:.2f} |", ns, ns / euler[s]);
        }
        std::cout << "\n";
    }
    std::cout << "\n(ns of the update loops per live drop per frame, median of 5 rounds of 20 frames)\n";
}

// Float state against @precision(double) (pairs of floats, opt/precision_double.cpp):
// errors measured on the state itself, so the doubles are not rounded to the drawn floats.
void precisionTable(Bench& bench, const std::string& dir, std::ofstream* csv) {
    const std::vector<Step>& steps = kSteps;
    std::cout << "\n### float state against @precision(double)\n\n| problem | method | state | ns/update at 1/60 |";
    const Step& sixty = steps[2];
    for (const Step& s : steps) std::cout << " " << s.label << " |";
    std::cout << " energy drift at 1/60 (orbit) |\n|---|---|---|---|";
    for (size_t i = 0; i <= steps.size(); ++i) std::cout << "---|";
    std::cout << "\n";
    for (const Problem& p : problems()) {
        std::string text = readFile(dir + "/" + p.file + ".psys");
        for (Integrator m : {Integrator::Rk4, Integrator::Leapfrog}) {
            for (bool pairs : {false, true}) {
                std::string stated = (pairs ? "@precision(double);\n" : "") + text;
                double cost = bench.cost(stated, p.type, m, sixty);
                std::cout << fmt::format("| {} | {} | {} | {:.2f} |", p.file, core::integratorName(m),
                                         pairs ? "double" : "float", cost);
                double drift = 0;
                for (const Step& s : steps) {
                    Measured r = bench.stateAccuracy(p, text, m, s, pairs);
                    if (&s == &sixty) drift = r.drift;
                    std::cout << " " << sci(r.maxError) << " / " << sci(r.finalError) << " |";
                    if (csv)
                        *csv << fmt::format("{},{}{},{},{},{},{},{},{},{}\n", p.file, core::integratorName(m),
                                            pairs ? " double" : "", s.label, s.frame, s.h(), r.maxError, r.finalError,
                                            cost, r.drift);
                }
                std::cout << " " << (p.file == "orbit" ? sci(drift) : "—") << " |\n";
            }
        }
    }
    std::cout << "\n(max / final error of the state against the exact solution: position in metres, the springs' x; "
                 "ns/update: one object's update at 1/60 s on the JIT, one thread)\n";
}

// What @tolerance chose for each problem at 1e-2, 1e-3 and 1e-4 m over its time, measured
// here on the JIT against the exact solution, and the cheapest method and sub-step that
// meets the tolerance found by brute force over every method at 1, 2, 4, 8 and 16
// sub-steps a frame of 1/60 s, in float and in double (the same measurements: largest
// error, ns per update).
void toleranceTable(Bench& bench, const std::string& dir, bool quick, bool explain) {
    const double frame = 1.0 / 60;
    std::cout << "\n### what @tolerance chooses, against the cheapest by brute force\n\n| problem | tolerance | chosen "
                 "| its error | its cost (ns/frame) | cheapest that meets it | its error | its cost | chosen / cheapest |\n"
                 "|---|---|---|---|---|---|---|---|---|\n";
    // A smoke test (--quick) brute-forces two problems: every candidate is a kernel to
    // compile, and the chooser's choice on every problem is tests/unit/tolerance_test.cpp's.
    size_t shown = 0;
    for (Problem p : problems()) {
        if (quick && shown++ == 2) break;
        if (p.drawn) p.error = p.drawn;
        std::string text = readFile(dir + "/" + p.file + ".psys");
        // Every candidate measured once: its largest error and its cost.
        struct Measure {
            Integrator method;
            int subSteps;
            core::Precision precision;
            double error, cost;
        };
        std::vector<Measure> all;
        auto withStep = [&](int s, core::Precision precision) {
            return (precision == core::Precision::Double ? "@precision(double);\n" : "") +
                   (s > 1 ? fmt::format("@step({});\n", frame / s) : "") + text;
        };
        const Step frames{"1/60", frame, false};
        for (core::Precision precision : {core::Precision::Float, core::Precision::Double})
            for (Integrator m : methods())
                for (int s : {1, 2, 4, 8, 16}) {
                    if (m == Integrator::Exact && s > 1) break;
                    Measured r = bench.accuracy(p, withStep(s, precision), m, frames);
                    if (!r.closedForm) break;
                    all.push_back({m, s, precision, r.maxError, bench.cost(withStep(s, precision), p.type, m, frames)});
                }
        for (double tolerance : {1e-2, 1e-3, 1e-4}) {
            SourceManager sources;
            DiagnosticEngine diags(sources);
            CompileOptions options;
            tune::TuneOptions tune;
            tune.frame = frame;
            std::vector<tune::Choice> choices;
            tune.pipeline = options.pipeline;
            options.beforePasses = [&](ir::Module& module, opt::PassErrors& messages) {
                choices = tune::chooseMethods(module, bench.jit(), tune, messages);
            };
            double seconds = quick ? std::min(p.seconds, 1.0) : p.seconds;  // as accuracy() runs it
            std::string stated = fmt::format("@tolerance({}, {});\n", tolerance, seconds) + text;
            if (!compileText("problem.psys", stated, sources, diags, options) || choices.size() != 1) std::exit(1);
            const tune::Choice& c = choices[0];
            if (explain) std::cerr << tune::explain(choices);
            const Measure* chosen = nullptr;
            const Measure* cheapest = nullptr;
            for (const Measure& m : all) {
                if (m.method == c.method && m.subSteps == c.subSteps && m.precision == c.precision) chosen = &m;
                if (m.error <= tolerance && (!cheapest || m.cost < cheapest->cost)) cheapest = &m;
            }
            if (!chosen) std::exit(1);
            std::cout << fmt::format("| {} | {:.0e} | {}{} | {} | {:.2f} |", p.file, tolerance,
                                     tune::describe(c.method, c.subSteps, frame, c.precision), c.met ? "" : " (warned: cannot meet)",
                                     sci(chosen->error), chosen->cost);
            if (cheapest)
                std::cout << fmt::format(" {} | {} | {:.2f} | {:.2f} |\n", tune::describe(cheapest->method, cheapest->subSteps, frame, cheapest->precision),
                                         sci(cheapest->error), cheapest->cost, chosen->cost / cheapest->cost);
            else
                std::cout << " none meets it | — | — | — |\n";
        }
    }
    std::cout << "\n(errors: the largest distance of the drawn point over the problem's time from its exact place — the springs draw (x, v, 0) — on the JIT; cost: ns of one "
                 "object's updates a frame of 1/60 s, one thread, 100 000 copies"
              << (quick ? "; --quick: the first two problems" : "") << ")\n";
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app("psys_accuracy: error against cost for every integration method");
    std::string csvPath, dir = PSYS_ACCURACY_DIR;
    size_t copies = 100000;
    bool quick = false, toleranceOnly = false, precisionOnly = false, explain = false;
    app.add_option("--csv", csvPath, "Write every measurement to FILE (for bench/plot_accuracy.py)");
    app.add_option("--copies", copies, "Objects per cost measurement (100000)");
    app.add_option("--problems", dir, "The folder of problem files (bench/accuracy)");
    app.add_flag("--quick", quick, "A smoke test: a second of each problem, few timed frames, the tolerance table for two problems (the figures mean nothing)");
    app.add_flag("--tolerance-only", toleranceOnly, "Only the table of what @tolerance chooses");
    app.add_flag("--precision-only", precisionOnly, "Only the table of float state against @precision(double)");
    app.add_flag("--explain", explain, "Print on stderr why @tolerance chose what it did (psysc check --explain)");
    CLI11_PARSE(app, argc, argv);
    std::ofstream csvFile;
    std::ofstream* csv = nullptr;
    if (!csvPath.empty()) {
        csvFile.open(csvPath);
        csvFile << "problem,method,step,frame,h,max_error,final_error,ns_per_update,extra\n";
        csv = &csvFile;
    }
    Bench bench(copies, quick);
    std::cout << fmt::format("# psys_accuracy on {}\n", bench.jit().report().target.empty() ? "this CPU"
                                                                                          : bench.jit().report().target);
    if (precisionOnly) {
        precisionTable(bench, dir, csv);
        return 0;
    }
    if (!toleranceOnly) {
        accuracyTables(bench, dir, csv);
        stiffTable(bench, dir, csv);
        fountainTable(bench, dir, quick);
        precisionTable(bench, dir, csv);
    }
    toleranceTable(bench, dir, quick, explain);
    return 0;
}
