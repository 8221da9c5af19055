// How the chooser runs its trials: tune/tolerance.h says why it works by trial.
#include "tune/tolerance.h"

#include <fmt/format.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <map>

#include "rt/pool.h"
#include "rt/system.h"

namespace psys::tune {

using core::Integrator;
using core::Precision;

namespace {

constexpr int kSubSteps[] = {1, 2, 4, 8, 16};

// The drawn positions of one type, frame by frame, sorted by object id.
using Frame = std::vector<std::pair<uint32_t, std::array<float, 3>>>;
using Path = std::vector<Frame>;

bool integrates(const ir::Object& object) {
    const ir::Kernel* behaviour = object.kernel(ir::KernelKind::Behaviour);
    if (!behaviour) return false;
    for (const ir::Inst& inst : behaviour->insts())
        if (inst.op == ir::Op::Integrate) return true;
    return false;
}

// A count as a person reads it: 60000, or 6e+21 past what anyone would count.
std::string count(double n) { return n < 1e9 ? fmt::format("{:.0f}", n) : fmt::format("{:.2g}", n); }

std::string seconds(double s) {
    double inverse = 1 / s;
    if (std::fabs(inverse - std::round(inverse)) < 1e-6 * inverse && inverse >= 2) return fmt::format("1/{:.0f}", inverse);
    return fmt::format("{:.4g}", s);
}

// The cost of one pass of an object's update (and exports), in adds on one lane: its
// arithmetic lane by lane — a library function (pow, sin, exp) 150, a division or a square
// root 4, the rest 1 — or, where that is more, the bytes of its row read and written (2 a
// byte): the JIT's vectorized loops are bound by one or the other. Calibrated on
// docs/accuracy.md's costs: the projectile's methods all cost what its memory does (about
// 1 ns for a row of 40 bytes), the orbit's what its pow does (3.5 ns an evaluation).
double passCost(const ir::Object& object) {
    double compute = 0;
    for (const ir::Kernel& k : object.kernels) {
        if (k.kind != ir::KernelKind::Update && k.kind != ir::KernelKind::Exports) continue;
        for (const ir::Inst& inst : k.insts()) {
            const core::OpInfo& info = core::opInfo(inst.op);
            double lanes = std::max<int>(1, inst.type.width);
            double weight = info.kind == core::OpKind::Random ? 10
                            : info.kind != core::OpKind::Pure ? 0
                            : inst.op == ir::Op::Div || inst.op == ir::Op::Sqrt ? 4
                            : !info.spelling.libm.empty() ? 150
                                                          : 1;
            compute += weight * lanes;
        }
    }
    double memory = 2.0 * 2 * static_cast<double>(rt::Pool::rowBytes(object));
    return std::max(compute, memory);
}

// bs3 holds its error within the object's tolerance (opt/integrate_adaptive.cpp): the one
// the chooser works to, stated where it came from --tolerance or the default time.
void stateTolerance(ir::Object& object, Integrator method, double tolerance, double over) {
    if (method != Integrator::Bs3) return;
    object.attributes.tolerance = static_cast<float>(tolerance);
    object.attributes.toleranceOver = static_cast<float>(over);
}

// A compiled candidate: the module with object `index` under `method`, and its cost.
struct Compiled {
    ir::Module module;
    double costPerUpdate = 0;
};

class Chooser {
public:
    // `spent`: the steps the program's trials ran so far — the budget is the program's.
    Chooser(const ir::Module& lowered, rt::Backend& backend, const TuneOptions& options, long& spent)
        : lowered_(lowered), backend_(backend), options_(options), steps_(spent), first_(spent) {}

    Choice choose(size_t index, double tolerance, double over, bool own) {
        const ir::Object& object = lowered_.objects[index];
        Choice c;
        c.object = object.name;
        c.loc = object.loc;
        tolerance_ = tolerance;
        over_ = over;
        c.tolerance = tolerance;
        c.over = over;
        c.frame = options_.frame;
        c.own = own;
        std::optional<Integrator> fixed = options_.pipeline.pass.everyObject;
        if (!fixed) fixed = object.attributes.integrator;
        c.methodFixed = fixed.has_value();
        c.precisionFixed = object.attributes.precision == Precision::Double;
        index_ = index;
        // (in double, and no more than the budget: a horizon of 1e20 s is no overflow)
        frames_ = static_cast<long>(std::clamp(std::ceil(over / options_.frame - 1e-9), 1.0,
                                               static_cast<double>(options_.budget) + 1));

        Path reference = referencePath(c);
        if (exhausted_) return finish(c);
        compared_ = 0;
        for (const Frame& f : reference) compared_ += f.size();

        for (Precision precision : {Precision::Float, Precision::Double}) {
            if (c.precisionFixed && precision == Precision::Float) continue;
            for (size_t m = 0; m < core::kIntegratorNames.size(); ++m) {
                auto method = static_cast<Integrator>(m);
                if (fixed && method != *fixed) continue;
                const Compiled* compiled = compile(method, precision);
                if (!compiled) continue;  // `exact` without a closed form
                for (int s : kSubSteps) {
                    if (method == Integrator::Exact && s > 1) break;  // the same at any step
                    c.trials.push_back({method, s, precision, compiled->costPerUpdate * s, std::nullopt});
                }
            }
        }
        std::stable_sort(c.trials.begin(), c.trials.end(),
                         [](const Trial& a, const Trial& b) { return a.cost < b.cost; });
        if (compared_ == 0 || !c.trusted) c.trials.clear();  // nothing to compare with: no choice
        if (c.trials.empty()) return finish(c);

        const Trial* chosen = nullptr;
        for (Trial& t : c.trials) {
            double budget = tolerance - c.floor;
            if (!(budget > 0)) break;
            t.error = run(compile(t.method, t.precision)->module, t.subSteps, &reference, budget).first + c.floor;
            if (exhausted_) return finish(c);
            if (*t.error <= tolerance) {
                chosen = &t;
                break;
            }
        }
        c.met = chosen != nullptr;
        if (!chosen) {  // the best it can do: every candidate, each stopped once it is behind the best
            double best = INFINITY;
            for (Trial& t : c.trials) {
                t.error = run(compile(t.method, t.precision)->module, t.subSteps, &reference, best).first + c.floor;
                if (exhausted_) return finish(c);
                if (*t.error < best || !chosen) {
                    best = std::min(best, *t.error);
                    chosen = &t;
                }
            }
        }
        c.method = chosen->method;
        c.subSteps = chosen->subSteps;
        c.precision = chosen->precision;
        c.error = *chosen->error;
        c.cost = chosen->cost;
        return finish(c);
    }

    bool drewNothing() const { return compared_ == 0 && !exhausted_; }
    // Whether the program compiled for the reference (else the real compile reports why).
    bool compiles() const { return compiles_; }

private:
    // The closed form where `exact` has one (its error float's rounding of a formula).
    // Else rk4 in double at 1, 2, 4 and 8 sub-steps a frame: the finer of the two
    // neighbours that agree best, their distance the reference's own error (`floor`) —
    // finer steps cut rk4's truncation by 16 each halving, while rounding grows with the
    // steps (in double far less than in float), so the best pair is where the two meet.
    Path referencePath(Choice& c) {
        if (const Compiled* exact = compile(Integrator::Exact)) {
            // A formula's few roundings: a handful of float's steps at the largest coordinate.
            Path path = run(exact->module, 1, nullptr, INFINITY).second;
            double largest = 0;
            for (const Frame& f : path)
                for (const auto& point : f)
                    for (float x : point.second) largest = std::max(largest, std::fabs(static_cast<double>(x)));
            c.reference = "the closed form (exact)";
            c.floor = 4 * FLT_EPSILON * largest;
            return path;
        }
        const Compiled* rk4 = compile(Integrator::Rk4, Precision::Double);
        compiles_ = rk4 != nullptr;
        if (!rk4) return {};  // the program does not compile (the real compile says why): nothing to compare
        Path coarser = run(rk4->module, 1, nullptr, INFINITY).second;
        Path best;
        c.floor = INFINITY;
        for (int s = 2; s <= 8; s *= 2) {
            Path finer = run(rk4->module, s, nullptr, INFINITY).second;
            double apart = pathDistance(finer, coarser);
            if (apart < c.floor) {
                c.floor = apart;
                c.reference = describe(Integrator::Rk4, s, options_.frame, Precision::Double);
                best = finer;
            }
            coarser = std::move(finer);
        }
        // A reference whose own error is a good part of what it draws has not settled at
        // any step (a stiff or unstable equation): nothing can be measured against it.
        for (const Frame& f : best)
            for (const auto& point : f)
                for (float x : point.second) c.largest = std::max(c.largest, std::fabs(static_cast<double>(x)));
        c.trusted = exhausted_ || c.floor == 0 || (std::isfinite(c.floor) && c.floor <= 0.01 * c.largest);
        return best;
    }

    Choice& finish(Choice& c) const {
        c.steps = steps_ - first_;
        c.exhausted = exhausted_;
        if (exhausted_) c.met = false;
        return c;
    }

    static double pathDistance(const Path& a, const Path& r) {
        double worst = 0;
        for (size_t f = 0; f < r.size(); ++f) worst = std::max(worst, distance(f < a.size() ? a[f] : Frame{}, r[f]));
        return worst;
    }

    // The module with the object under `method` in `precision` (compiled once), or null
    // where the passes refuse it (`exact` without a closed form).
    const Compiled* compile(Integrator method, Precision precision = Precision::Float) {
        if (auto it = modules_.find({method, precision}); it != modules_.end()) return it->second ? &*it->second : nullptr;
        std::optional<Compiled>& slot = modules_[{method, precision}];
        ir::Module module = lowered_;
        opt::PipelineOptions pipeline = options_.pipeline;
        // A method for every object (--integrator) stays every other object's; this one
        // takes the candidate's (the reference's: it is compared with the method asked).
        for (ir::Object& o : module.objects) {
            if (pipeline.pass.everyObject) o.attributes.integrator = pipeline.pass.everyObject;
            // A trial's population stays small: the chooser looks at the first objects alone.
            o.attributes.capacity = std::min<uint64_t>(o.attributes.capacity.value_or(options_.population), options_.population);
        }
        pipeline.pass.everyObject.reset();
        module.objects[index_].attributes.integrator = method;
        module.objects[index_].attributes.precision = precision;
        stateTolerance(module.objects[index_], method, tolerance_, over_);
        pipeline.log = nullptr;
        pipeline.printAfter.clear();
        pipeline.printAfterAll = false;
        opt::PassErrors ignored;  // the real compile reports them
        if (!opt::runPipeline(module, pipeline, ignored)) return nullptr;
        slot = Compiled{std::move(module), 0};
        slot->costPerUpdate = passCost(slot->module.objects[index_]);
        return &*slot;
    }

    // Runs a candidate at `subSteps` a frame: its largest distance from `reference` (0
    // without one; stopped once past `stop`), and its path.
    std::pair<double, Path> run(const ir::Module& compiled, int subSteps, const Path* reference, double stop) {
        ir::Module module = compiled;
        module.objects[index_].attributes.step = subSteps > 1 ? static_cast<float>(options_.frame / subSteps) : 0;
        rt::SystemOptions system;
        system.threads = 1;
        system.capacity = options_.population;
        rt::System s(std::move(module), backend_, system);
        Path path;
        double worst = 0;
        const std::string& name = lowered_.objects[index_].name;
        size_t type = static_cast<size_t>(s.typeIndex(name));
        for (long f = 0; f < frames_; ++f) {
            steps_ += subSteps;
            if (steps_ > options_.budget || (options_.cancelled && options_.cancelled->load(std::memory_order_relaxed))) {
                exhausted_ = true;
                return {INFINITY, path};
            }
            if (s.step(options_.frame)) return {INFINITY, path};
            Frame frame;
            for (const rt::RenderPoint& p : s.points(type)) frame.push_back({p.id, p.position});
            std::sort(frame.begin(), frame.end(), [](auto& a, auto& b) { return a.first < b.first; });
            if (reference) {
                const Frame& r = f < static_cast<long>(reference->size()) ? (*reference)[f] : Frame{};
                worst = std::max(worst, distance(frame, r));
                if (worst > stop) return {worst, path};
            } else {
                path.push_back(std::move(frame));
            }
            if (s.finished()) break;
        }
        return {worst, path};
    }

    // The largest distance between the objects two frames both draw; an object the
    // reference draws that the other does not (killed or not yet created by the method's
    // error) is infinitely far.
    static double distance(const Frame& a, const Frame& r) {
        double worst = 0;
        size_t i = 0;
        for (const auto& [id, q] : r) {
            while (i < a.size() && a[i].first < id) ++i;
            if (i == a.size() || a[i].first != id) return INFINITY;
            const auto& p = a[i].second;
            double dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
            double d = std::sqrt(dx * dx + dy * dy + dz * dz);
            worst = std::isnan(d) ? INFINITY : std::max(worst, d);
        }
        return worst;
    }

    const ir::Module& lowered_;
    rt::Backend& backend_;
    const TuneOptions& options_;
    size_t index_ = 0;
    double tolerance_ = 0, over_ = 0;
    long frames_ = 0;
    long& steps_;
    const long first_;
    bool exhausted_ = false;
    size_t compared_ = 0;
    std::map<std::pair<Integrator, Precision>, std::optional<Compiled>> modules_;
    bool compiles_ = true;
};

}  // namespace

std::string describe(Integrator method, int subSteps, double frame, Precision precision) {
    std::string name(core::integratorName(method));
    if (precision == Precision::Double) name += " in double (@precision(double))";
    if (subSteps <= 1) return name;
    return fmt::format("{} with {} sub-steps a frame (@step({}))", name, subSteps, seconds(frame / subSteps));
}

std::vector<Choice> chooseMethods(ir::Module& module, rt::Backend& backend, const TuneOptions& options,
                                  opt::PassErrors& messages) {
    std::vector<Choice> choices;
    long spent = 0;  // one budget for the program, whatever the number of objects under a tolerance
    for (size_t i = 0; i < module.objects.size(); ++i) {
        if (options.cancelled && options.cancelled->load(std::memory_order_relaxed)) break;
        ir::Object& object = module.objects[i];
        bool own = object.attributes.tolerance > 0;
        double tolerance = own ? object.attributes.tolerance : options.tolerance;
        if (!(tolerance > 0) || !integrates(object)) continue;
        double over = own && object.attributes.toleranceOver > 0 ? object.attributes.toleranceOver : options.horizon;
        Chooser chooser(module, backend, options, spent);
        Choice c = chooser.choose(i, tolerance, over, own);
        if (!chooser.compiles()) continue;  // its errors are the compile's, not the chooser's
        if (c.exhausted) {
            if (!(options.cancelled && options.cancelled->load()))
                messages.warning(object.loc,
                                 fmt::format("the trials for `{}`'s tolerance over {:.4g} s stopped at their budget of "
                                             "{} steps before a choice (a trial runs {} frames of up to 16 sub-steps): "
                                             "its integrator and step stay as written; a shorter horizon is measured in full",
                                             object.name, over, options.budget, count(std::ceil(over / options.frame - 1e-9))),
                                 object.name);
            choices.push_back(std::move(c));
            continue;
        }
        if (!c.trusted) {
            messages.warning(object.loc,
                             fmt::format("`{}`'s error cannot be measured: the reference, rk4 in double, does not settle "
                                         "at any sub-step up to 8 a frame (its paths at two neighbouring sub-steps are at "
                                         "best {:.2g} m apart, for coordinates of at most {:.2g} m): a stiff or unstable "
                                         "equation? Its integrator and step stay as written",
                                         object.name, c.floor, c.largest),
                             object.name);
            choices.push_back(std::move(c));
            continue;
        }
        if (chooser.drewNothing()) {
            messages.warning(object.loc, fmt::format("`{}` draws nothing in its first {} s: its tolerance cannot be "
                                                     "measured, and its integrator and step stay as written",
                                                     object.name, fmt::format("{:.4g}", over)));
            choices.push_back(std::move(c));
            continue;
        }
        if (c.trials.empty()) continue;
        object.attributes.integrator = c.method;
        object.attributes.step = c.subSteps > 1 ? static_cast<float>(options.frame / c.subSteps) : 0;
        object.attributes.precision = c.precision;
        stateTolerance(object, c.method, tolerance, over);
        if (!c.met) {
            std::string why = c.floor * 2 >= tolerance
                                  ? fmt::format("the reference itself, {}, is only good to about {:.2g} m here",
                                                c.reference, c.floor)
                              : c.methodFixed ? std::string("the integrator is the one written, by @integrator or "
                                                            "--integrator, and only the sub-step was chosen")
                                              : std::string("no finer sub-step than 1/16 of a frame is tried");
            messages.warning(object.loc,
                             fmt::format("no integrator and sub-step keeps `{}` within {:.3g} m over {:.4g} s at frames "
                                         "of {} s: the closest, {}, is within {:.2g} m ({})",
                                         object.name, tolerance, over, seconds(options.frame),
                                         describe(c.method, c.subSteps, options.frame, c.precision), c.error, why),
                             object.name);
        }
        choices.push_back(std::move(c));
    }
    return choices;
}

std::string explain(const std::vector<Choice>& choices) {
    std::string out;
    for (const Choice& c : choices) {
        out += fmt::format("{}: @tolerance({:.3g} m over {:.4g} s){}: ", c.object, c.tolerance, c.over,
                           c.own ? "" : " (the default)");
        if (c.exhausted) {
            out += fmt::format("stopped at the budget of trial steps ({} run); integrator and step as written\n", c.steps);
            continue;
        }
        if (!c.trusted) {
            out += fmt::format("the reference does not settle ({}, its own error about {:.2g} m on coordinates up to "
                               "{:.2g} m); integrator and step as written\n", c.reference, c.floor, c.largest);
            continue;
        }
        if (c.trials.empty()) {
            out += "nothing drawn to measure; integrator and step as written\n";
            continue;
        }
        out += fmt::format("{} {}, error {:.2g} m, cost {:.0f} a frame{}\n", c.met ? "chose" : "cannot meet it; closest",
                           describe(c.method, c.subSteps, c.frame, c.precision), c.error, c.cost,
                           c.methodFixed ? " (the integrator as written; the sub-step chosen)" : "");
        out += fmt::format("  reference: {}, its own error about {:.2g} m; {} trial steps\n", c.reference, c.floor,
                           c.steps);
        for (const Trial& t : c.trials) {
            if (!t.error) continue;
            std::string error = !std::isfinite(*t.error)     ? "unbounded"
                                : *t.error > c.tolerance ? fmt::format("over {:.2g} m (stopped)", *t.error)
                                                         : fmt::format("{:.2g} m", *t.error);
            out += fmt::format("  tried {:<50} cost {:>5.0f} a frame, error {}\n",
                               describe(t.method, t.subSteps, c.frame, t.precision), t.cost, error);
        }
    }
    return out;
}

}  // namespace psys::tune
