// The generator: a model of a program (types, their equations, draws, kills and emits,
// triggers, externs, spawns) drawn from the seed, printed as text; the edit is the same
// model changed once and printed again.
#include "tools/progen/generator.h"

#include <algorithm>
#include <functional>
#include <regex>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "tools/progen/model.h"

namespace psys::progen {

namespace {

// splitmix64: the same draws on every platform (the standard distributions are not).
class Rng {
public:
    explicit Rng(uint64_t seed) : s_(seed) {}
    uint64_t next() {
        uint64_t z = (s_ += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    size_t below(size_t n) { return n == 0 ? 0 : static_cast<size_t>(next() % n); }
    int between(int lo, int hi) { return lo + static_cast<int>(below(static_cast<size_t>(hi - lo + 1))); }
    bool chance(double p) { return static_cast<double>(next() >> 11) / 9007199254740992.0 < p; }
    // A number in [lo, hi] with three decimals: off the frames' times (k/60 s) but for chance.
    double real(double lo, double hi) {
        double u = static_cast<double>(next() >> 11) / 9007199254740992.0;
        return std::round((lo + u * (hi - lo)) * 1000 + 0.37) / 1000;
    }
    template <typename T>
    const T& pick(const std::vector<T>& v) {
        return v[below(v.size())];
    }

private:
    uint64_t s_;
};

class Builder {
public:
    Builder(uint64_t seed, bool ageControlled)
        : r_(seed), more_(seed ^ 0x5eed5eed5eed5eedull), events_(seed ^ 0xe7e27e27e27e27e2ull),
          folds_(seed ^ 0xf01df01df01df01dull), age_(ageControlled) {}

    Model build() {
        int externs = r_.between(0, 2);
        for (int i = 0; i < externs; ++i) {
            Extern e;
            e.name = fmt::format("e{}", i);
            e.ty = r_.chance(0.5) ? Ty::Float : Ty::Vec3;
            e.lo = e.ty == Ty::Float ? 0 : -2;
            e.hi = e.ty == Ty::Float ? r_.between(2, 4) : 2;
            e.def = e.ty == Ty::Float ? 1 : 0;
            m_.externs.push_back(e);
        }
        // A flat program (3 in 10): top-level types only, most emitting others — where the
        // memory decides emitters' emissions (on the GPU; SystemOptions::Rows::InMemory on
        // the interpreter). Drawn from a stream of its own, as the extra sites are.
        flat_ = more_.chance(0.3);
        int tops = r_.between(flat_ ? 2 : 1, 4);
        for (int i = 0; i < tops; ++i) addType(-1);
        for (size_t t = 0; t < m_.types.size(); ++t) fillType(static_cast<int>(t));
        foldsOverLaterTypes();
        int triggers = r_.between(0, 2);
        for (int i = 0; i < triggers; ++i) addTrigger(i);
        addSpawns();
        capPopulations();
        notifications();
        if (r_.chance(0.1)) m_.fileAttr = r_.pick(std::vector<std::string>{"@integrator(rk4);", "@integrator(midpoint);", "@integrator(euler);"});
        return m_;
    }

    // The edit: one change a user makes while the system runs.
    void edit(Model& m) {
        m_ = m;
        bool done = false;
        for (int tries = 0; tries < 8 && !done; ++tries) done = editOnce(r_.below(6));
        if (!done) changeTerm();
        capPopulations();  // an edit may start a type the program never started (seed 940130)
        m = m_;
    }

private:
    Rng r_, more_;
    Rng events_;  // notifications and instances: a stream of their own (every seed's program is otherwise what it was)
    Rng folds_;   // folds over types declared later: the same
    bool age_, flat_ = false;
    Model m_;

    std::vector<int> tops() const {
        std::vector<int> out;
        for (size_t i = 0; i < m_.types.size(); ++i)
            if (m_.types[i].parent < 0 && !m_.types[i].removed) out.push_back(static_cast<int>(i));
        return out;
    }

    int addType(int parent) {
        Type t;
        t.parent = parent;
        t.depth = parent < 0 ? 0 : m_.types[static_cast<size_t>(parent)].depth + 1;
        t.name = parent < 0 ? fmt::format("t{}", m_.types.size()) : fmt::format("n{}", m_.types.size());
        int params = r_.between(0, 2);
        for (int i = 0; i < params; ++i) t.params.push_back({fmt::format("p{}", i), r_.chance(0.6) ? Ty::Vec3 : Ty::Float});
        m_.types.push_back(t);
        int index = static_cast<int>(m_.types.size()) - 1;
        if (parent >= 0) m_.types[static_cast<size_t>(parent)].children.push_back(index);
        // Nested children, up to three levels below a top-level type (none in a flat program).
        if (!flat_ && t.depth < 3 && r_.chance(t.depth == 0 ? 0.45 : 0.3)) {
            int children = r_.between(1, 2);
            for (int i = 0; i < children; ++i) addType(index);
        }
        return index;
    }

    std::string vec3Param(const Type& t) const {
        for (const Param& p : t.params)
            if (p.ty == Ty::Vec3) return p.name;
        return "";
    }
    std::string floatParam(const Type& t) const {
        for (const Param& p : t.params)
            if (p.ty == Ty::Float) return p.name;
        return "";
    }
    std::string externOf(Ty ty) const {
        for (const Extern& e : m_.externs)
            if (e.ty == ty) return e.name;
        return "";
    }
    std::string vec(double lo, double hi) { return fmt::format("vec3({}, {}, {})", num(r_.real(lo, hi)), num(r_.real(lo, hi)), num(r_.real(lo, hi))); }

    // Equations: positions and velocities from exact operations only (the file's header).
    void equations(Type& t) {
        const std::string p3 = vec3Param(t), pf = floatParam(t);
        const std::string parent = t.parent >= 0 ? m_.types[static_cast<size_t>(t.parent)].name : "";
        const std::string wind = externOf(Ty::Vec3);
        std::string start = !p3.empty() && r_.chance(0.7) ? p3 : vec(-1, 1);
        switch (r_.below(parent.empty() ? 3 : 4)) {
            case 0:
            case 1: {
                t.hasVel = true;
                t.equations.push_back(fmt::format("pos = snapshot({}) + integrate(vel);", start));
                std::string v0 = r_.chance(0.5) ? fmt::format("snapshot(nrand3() * {})", num(r_.real(0.2, 3))) : vec(-2, 3);
                std::string acc = fmt::format("vec3(0, {}, 0)", num(-r_.real(0, 9.8)));
                if (!wind.empty() && r_.chance(0.5)) acc += " + " + wind;
                if (r_.chance(0.5)) acc += fmt::format(" - vel * {}", num(r_.real(0.1, 2)));
                t.equations.push_back(fmt::format("vel = {} + integrate({});", v0, acc));
                break;
            }
            case 2:
                t.equations.push_back(fmt::format("pos = {} + vec3(age * {}, age * {}, {});", start, num(r_.real(-2, 2)),
                                                  num(r_.real(-2, 2)), pf.empty() ? num(r_.real(-1, 1)) : pf));
                break;
            case 3:  // follows its parent live (frozen after it dies), and its grandparent's age
                t.equations.push_back(fmt::format("pos = {}.pos + {} * (1 + age){};", parent, !p3.empty() ? p3 : vec(-0.5, 0.5),
                                                  grandparentAge(t)));
                break;
        }
        if (r_.chance(0.3)) t.equations.push_back("n = 0 -> prev(n) + 1;");
        if (r_.chance(0.3)) t.equations.push_back(fmt::format("w = snapshot(rand() * {});", num(r_.real(0.5, 3))));
        if (t.parent >= 0 && r_.chance(0.3)) t.equations.push_back(fmt::format("pa = {}.age;", parent));
    }

    bool has(const Type& t, const std::string& name) const {
        for (const std::string& e : t.equations)
            if (e.rfind(name + " =", 0) == 0) return true;
        return false;
    }

    std::string colour(const Type& t) {
        std::vector<std::string> c = {"white", "red", "cyan", "orange", "vec4(0.5, 0.8, 1, 1 - age * 0.3)",
                                      "vec4(0.5 + 0.5 * sin(age * 3), 0.4, exp(-age), 1)",
                                      "vec4(1, pow(0.5, age + 1), sqrt(age + 1) * 0.2, 1)"};
        std::string out = r_.pick(c);
        if (t.foldOver >= 0) out = "vec4(1, 1, 1, 1 / (1 + crowd))";
        return out;
    }

    void drawCommand(Type& t) {
        if (r_.chance(0.12) && t.foldOver < 0) return;  // draws nothing
        std::string size = r_.chance(0.5) ? num(r_.real(1, 4)) : fmt::format("{} + sin(age) * 0.5", num(r_.real(1, 3)));
        switch (r_.below(t.hasVel ? 4 : 3)) {
            case 0: t.draw = fmt::format("point(pos, {}, {});", colour(t), size); break;
            case 1: t.draw = fmt::format("sprite(pos, {}, {}, age * {});", colour(t), num(r_.real(0.05, 0.4)), num(r_.real(0, 3))); break;
            case 2: t.draw = fmt::format("trail(pos, {}, {}, {});", colour(t), num(r_.real(0.01, 0.1)), r_.between(2, 9)); break;
            case 3: t.draw = fmt::format("streak(pos - vel * 0.03, pos, {}, {});", colour(t), num(r_.real(0.01, 0.05))); break;
        }
    }

    // Reads of a grandparent (two levels up), drawn from the second stream, as the extra
    // sites are: a program whose types are nested less deeply is the one it was.
    std::string grandparent(const Type& t) const {
        if (t.depth < 2) return "";
        return m_.types[static_cast<size_t>(m_.types[static_cast<size_t>(t.parent)].parent)].name;
    }
    std::string grandparentAge(const Type& t) {
        std::string g = grandparent(t);
        return !g.empty() && more_.chance(0.4) ? fmt::format(" + vec3(0, {}.age * {}, 0)", g, num(more_.real(0.1, 1))) : "";
    }

    // A condition a kill or an edge decides by (or, sometimes, a grandparent's death).
    std::string condition(const Type& t, double lo, double hi) {
        std::string c = ownCondition(t, lo, hi), g = grandparent(t);
        if (!g.empty() && more_.chance(0.25)) c = fmt::format("{} || (!{}.alive && age > {})", c, g, num(more_.real(lo / 2, hi / 2)));
        return c;
    }
    std::string ownCondition(const Type& t, double lo, double hi) {
        std::string c = fmt::format("age > {}", num(r_.real(lo, hi)));
        if (age_) {
            if (t.parent >= 0 && r_.chance(0.3))
                c = fmt::format("{} || (!{}.alive && age > {})", c, m_.types[static_cast<size_t>(t.parent)].name,
                                num(r_.real(lo / 2, hi / 2)));
            return c;
        }
        switch (r_.below(6)) {
            case 0: return fmt::format("age > {} + rand() * {}", num(r_.real(lo, hi)), num(r_.real(0.05, 0.5)));
            case 1: return fmt::format("pos.y < {}", num(r_.real(-3, -0.5)));
            case 2: if (has(t, "n")) return fmt::format("n > {}", r_.between(3, 90)); break;
            case 3: if (has(t, "w")) return fmt::format("age > w + {}", num(r_.real(0, lo))); break;
            case 4: return fmt::format("fract(age * {}) > 0.5", num(r_.real(0.3, 4)));
            case 5: if (t.parent >= 0) return fmt::format("!{}.alive", m_.types[static_cast<size_t>(t.parent)].name); break;
        }
        return c;
    }

    // Arguments for `params` from a scope: an object type's (t >= 0), a trigger's (its
    // params), or the start's.
    std::vector<std::string> args(int t, const std::vector<Param>& params, const Trigger* trigger = nullptr) {
        std::vector<std::string> out;
        for (const Param& p : params) {
            if (p.ty == Ty::Vec3) {
                std::string base;
                if (t >= 0) base = "pos";
                if (trigger)
                    for (const Param& q : trigger->params)
                        if (q.ty == Ty::Vec3) base = q.name;
                if (base.empty()) base = vec(-1, 1);
                out.push_back(r_.chance(0.7) ? fmt::format("{} + nrand3() * {}", base, num(r_.real(0.05, 0.8))) : base);
            } else {
                std::string e = externOf(Ty::Float);
                if (!e.empty() && r_.chance(0.3)) out.push_back(e);
                else out.push_back(fmt::format("rand() * {}", num(r_.real(0.5, 2))));
            }
        }
        return out;
    }

    Emit emitTo(int from, int target) {
        Emit e;
        e.target = target;
        const Type& t = m_.types[static_cast<size_t>(from)];
        bool dies = !t.kills.empty() || !t.whenKill.empty();
        e.kind = static_cast<Emit::Kind>(r_.below(dies ? 5 : 4));
        std::string ef = externOf(Ty::Float);
        double rate = r_.pick(std::vector<double>{0.7, 3, 12.5, 40, 90, 200});
        e.rate = !ef.empty() && r_.chance(0.3) ? fmt::format("{} * {}", num(rate / 2), ef) : num(rate);
        e.count = std::to_string(r_.pick(std::vector<int>{1, 2, 3, 7, 20, 40}));
        e.cond = condition(t, 0.1, 1.5);
        e.args = args(from, m_.types[static_cast<size_t>(target)].params);
        return e;
    }

    // Half the folds retargeted at a top-level type declared after theirs (once every
    // type's draw is known: both must draw), and where that one folds too, it sometimes
    // back at this one: predators and prey.
    void foldsOverLaterTypes() {
        auto retarget = [&](int index, int over) {
            Type& t = m_.types[static_cast<size_t>(index)];
            const std::string& from = m_.types[static_cast<size_t>(t.foldOver)].name;
            for (std::string& e : t.equations)
                if (e.rfind("crowd = near_count(" + from + ",", 0) == 0)
                    e = "crowd = near_count(" + m_.types[static_cast<size_t>(over)].name + e.substr(19 + from.size());
            t.foldOver = over;
        };
        for (int index : tops()) {
            Type& t = m_.types[static_cast<size_t>(index)];
            if (t.foldOver < 0 || !folds_.chance(0.5)) continue;
            std::vector<int> later;
            for (int o : tops())
                if (o > index && !m_.types[static_cast<size_t>(o)].draw.empty()) later.push_back(o);
            if (later.empty()) continue;
            int over = folds_.pick(later);
            retarget(index, over);
            if (m_.types[static_cast<size_t>(over)].foldOver >= 0 && folds_.chance(0.5)) retarget(over, index);
        }
    }

    void fillType(int index) {
        Type& t = m_.types[static_cast<size_t>(index)];
        equations(t);
        // A fold over its own type or one declared before it (fewer in a flat program: what
        // is folded over exports, and an emitter that dies and exports is the host's);
        // foldsOverLaterTypes turns some to types declared after.
        if (t.parent < 0 && r_.chance(flat_ ? 0.05 : 0.15)) {
            std::vector<int> over;
            for (int o : tops())  // both must draw: near is measured between drawn positions
                if (o == index || (o < index && !m_.types[static_cast<size_t>(o)].draw.empty())) over.push_back(o);
            t.foldOver = r_.pick(over);
            t.equations.push_back(fmt::format("crowd = near_count({}, {});", m_.types[static_cast<size_t>(t.foldOver)].name,
                                              num(r_.real(0.2, 1.5))));
        }
        drawCommand(t);
        if (r_.chance(0.8)) t.kills.push_back(condition(t, 0.05, 2.5));
        if (r_.chance(0.1)) t.whenKill = condition(t, 0.2, 2);
        // Emits: its own children always (only it can create them), other top-level types
        // sometimes.
        for (int child : t.children) {
            int n = r_.between(1, 2);
            for (int i = 0; i < n; ++i) t.emits.push_back(emitTo(index, child));
        }
        // (A flat program's types emit only those after them: chains that end in types
        // emitting nothing, as the memory's emitters need. A nested type with no children
        // emits less often: children that emit nothing, their parents emitters, keep their
        // rows in the memory too.)
        std::vector<int> targets = tops();
        if (flat_) std::erase_if(targets, [&](int o) { return o <= index; });
        bool leaf = t.parent >= 0 && t.children.empty();
        if (!targets.empty() && r_.chance(flat_ ? 0.8 : leaf ? 0.15 : 0.4)) {
            t.emits.push_back(emitTo(index, r_.pick(targets)));
            // Half of the top-level types that have no children of their own (emitters
            // whose emissions the memory may decide) one or two more, so that sites share
            // a target's room and an emitter emits two types of emitters (what the
            // memory's operation must order as the host does) — drawn from a stream of
            // their own, so that every seed's program is otherwise what it was.
            std::swap(r_, more_);
            if (t.parent < 0 && t.children.empty() && r_.chance(0.5))
                for (int i = r_.between(1, 2); i > 0; --i) t.emits.push_back(emitTo(index, r_.pick(targets)));
            std::swap(r_, more_);
        }
        for (const std::string& a : attributes(t)) t.attrs.push_back(a);
    }

    // Some types tell the host what happens (`notify`: in the body, in a `when`, `on death`),
    // and some programs are instanced (their draws at `instance.pos`): the case then plays
    // instances, stops and kills them (generate()).
    void notifications() {
        Rng& r = events_;
        for (size_t i = 0; i < m_.types.size(); ++i) {
            Type& t = m_.types[i];
            if (!r.chance(0.25)) continue;
            switch (r.below(3)) {
                case 0: t.notifies.push_back(fmt::format("notify \"seen{}\"(pos, age);", i)); break;
                case 1:
                    t.notifies.push_back(fmt::format("when age > {} {{ notify \"old{}\"(age); }}", num(r.real(0.05, 1)), i));
                    break;
                default: t.deathNotifies.push_back(fmt::format("notify \"gone{}\"(pos.y);", i)); break;
            }
        }
        if (!r.chance(0.2)) return;
        m_.instanced = true;
        for (Type& t : m_.types)
            if (!t.draw.empty()) t.draw = std::regex_replace(t.draw, std::regex("^(\\w+)\\(pos"), "$1(instance.pos + pos");
    }

    std::vector<std::string> attributes(const Type& t) {
        std::vector<std::string> out;
        if (r_.chance(0.15)) out.push_back(r_.chance(0.5) ? "@step(1 / 240)" : "@step(0.007)");
        if (t.hasVel && r_.chance(0.2))
            out.push_back(fmt::format("@integrator({})", r_.pick(std::vector<std::string>{"euler", "midpoint", "rk4", "semi_implicit"})));
        if (r_.chance(0.2)) out.push_back(fmt::format("@capacity({})", r_.pick(std::vector<int>{3, 10, 50, 400})));
        return out;
    }

    void addTrigger(int i) {
        Trigger tr;
        tr.name = fmt::format("fire{}", i);
        if (r_.chance(0.7)) tr.params.push_back({"where", Ty::Vec3});
        if (r_.chance(0.4)) tr.params.push_back({"s", Ty::Float});
        int target = r_.pick(tops());
        Emit e;
        e.kind = Emit::Burst;
        e.target = target;
        e.count = std::to_string(r_.pick(std::vector<int>{1, 5, 40}));
        e.args = args(-1, m_.types[static_cast<size_t>(target)].params, &tr);
        tr.emits.push_back(e);
        m_.triggers.push_back(tr);
    }

    void addSpawns() {
        std::vector<int> t = tops();
        int n = r_.between(1, 3);
        for (int i = 0; i < n; ++i) {
            int type = r_.pick(t);
            m_.spawns.push_back({type, args(-1, m_.types[static_cast<size_t>(type)].params)});
        }
    }

    // A bound on each type's objects: where emitters of emitters multiply past a few
    // thousand (or a type emits itself), a capacity. What triggers create counts as a
    // start as spawns do (a type only a trigger created once emitted itself at 200 a
    // second uncapped: a million objects, and the case timed out).
    void capPopulations() {
        std::vector<double> pop(m_.types.size(), 0);
        for (const auto& s : m_.spawns) pop[static_cast<size_t>(s.first)] += 1;
        for (const Trigger& tr : m_.triggers)
            for (const Emit& e : tr.emits) pop[static_cast<size_t>(e.target)] += 40;
        for (int round = 0; round < 6; ++round)
            for (size_t from = 0; from < m_.types.size(); ++from)
                for (const Emit& e : m_.types[from].emits) {
                    double each = (e.kind == Emit::Rate || e.kind == Emit::RateCount) ? 200.0 * 3 : 40;
                    pop[static_cast<size_t>(e.target)] = std::min(1e9, pop[static_cast<size_t>(e.target)] + pop[from] * each);
                }
        for (size_t t = 0; t < m_.types.size(); ++t) {
            bool capped = std::any_of(m_.types[t].attrs.begin(), m_.types[t].attrs.end(),
                                      [](const std::string& a) { return a.rfind("@capacity", 0) == 0; });
            if (pop[t] > 3000 && !capped) m_.types[t].attrs.push_back(fmt::format("@capacity({})", r_.between(5, 2000)));
        }
    }

    // Edits: each returns whether it found something to change.
    bool editOnce(size_t kind) {
        switch (kind) {
            case 0: return changeTerm();
            case 1: return addEquation();
            case 2: return removeEquation();
            case 3: return removeType();
            case 4: return addSpawnedType();
            default: return renameParam();
        }
    }
    // A new top-level type (and its nested ones), spawned.
    bool addSpawnedType() {
        size_t first = m_.types.size();
        int added = addType(-1);
        for (size_t t = first; t < m_.types.size(); ++t) fillType(static_cast<int>(t));
        m_.spawns.push_back({added, args(-1, m_.types[static_cast<size_t>(added)].params)});
        return true;
    }
    std::vector<int> live() const {
        std::vector<int> out;
        for (size_t i = 0; i < m_.types.size(); ++i)
            if (!m_.types[i].removed) out.push_back(static_cast<int>(i));
        return out;
    }
    bool changeTerm() {
        Type& t = m_.types[static_cast<size_t>(r_.pick(live()))];
        std::vector<std::string*> lines;
        for (std::string& e : t.equations) lines.push_back(&e);
        if (!t.draw.empty()) lines.push_back(&t.draw);
        std::string& line = *lines[r_.below(lines.size())];
        std::regex number(R"((\d+\.\d+|\b\d+\b))");
        std::smatch m;
        if (!std::regex_search(line, m, number)) return false;
        line = std::string(m.prefix()) + num(r_.real(0.1, 3)) + std::string(m.suffix());
        return true;
    }
    bool addEquation() {
        Type& t = m_.types[static_cast<size_t>(r_.pick(live()))];
        if (has(t, "extra")) return false;
        t.equations.push_back(r_.chance(0.5) ? "extra = integrate(vec3(1, 0, 0));" : "extra = 0 -> prev(extra) + 0.5;");
        return true;
    }
    bool removeEquation() {
        Type& t = m_.types[static_cast<size_t>(r_.pick(live()))];
        for (size_t i = 0; i < t.equations.size(); ++i) {
            std::string name = t.equations[i].substr(0, t.equations[i].find(' '));
            if (name != "w" && name != "pa" && name != "n") continue;
            std::regex use("\\b" + name + "\\b");
            bool used = false;
            for (size_t j = 0; j < t.equations.size(); ++j) used |= j != i && std::regex_search(t.equations[j], use);
            for (const std::string& k : t.kills) used |= std::regex_search(k, use);
            for (const Emit& e : t.emits) used |= std::regex_search(e.cond, use);
            used |= std::regex_search(t.whenKill, use);
            if (used) continue;
            t.equations.erase(t.equations.begin() + static_cast<std::ptrdiff_t>(i));
            return true;
        }
        // No such state: the drag goes, or the start becomes a plain value (what hot
        // reload must carry or start again).
        for (std::string& e : t.equations)
            if (e.rfind("pos = snapshot(", 0) == 0) {
                e = "pos = snapshot(" + e.substr(15, e.find(") + integrate") - 15) + ");";
                return true;
            }
        return false;
    }
    bool removeType() {
        std::vector<int> t = tops();
        if (t.size() < 2) return false;
        int gone = r_.pick(t);
        std::function<void(int)> drop = [&](int i) {
            m_.types[static_cast<size_t>(i)].removed = true;
            for (int c : m_.types[static_cast<size_t>(i)].children) drop(c);
        };
        drop(gone);
        for (Type& ty : m_.types) {
            std::erase_if(ty.emits, [&](const Emit& e) { return m_.types[static_cast<size_t>(e.target)].removed; });
            if (ty.foldOver >= 0 && m_.types[static_cast<size_t>(ty.foldOver)].removed)
                for (std::string& e : ty.equations)
                    if (e.rfind("crowd =", 0) == 0) e = "crowd = 0;";
        }
        for (Trigger& tr : m_.triggers)
            std::erase_if(tr.emits, [&](const Emit& e) { return m_.types[static_cast<size_t>(e.target)].removed; });
        std::erase_if(m_.spawns, [&](const auto& s) { return m_.types[static_cast<size_t>(s.first)].removed; });
        if (m_.spawns.empty()) m_.spawns.push_back({tops()[0], args(-1, m_.types[static_cast<size_t>(tops()[0])].params)});
        return true;
    }
    bool renameParam() {
        for (int i : live()) {
            Type& t = m_.types[static_cast<size_t>(i)];
            if (t.params.empty()) continue;
            Param& p = t.params[0];
            std::string to = p.name + "r";
            std::regex own("\\b" + p.name + "\\b"), read("\\b" + t.name + "\\." + p.name + "\\b");
            auto rename = [&](std::string& s) { s = std::regex_replace(s, own, to); };
            for (std::string& e : t.equations) rename(e);
            rename(t.draw);
            for (std::string& k : t.kills) rename(k);
            rename(t.whenKill);
            for (Emit& e : t.emits) {
                rename(e.cond);
                for (std::string& a : e.args) rename(a);
            }
            for (int c : t.children)
                for (std::string& e : m_.types[static_cast<size_t>(c)].equations) e = std::regex_replace(e, read, t.name + "." + to);
            p.name = to;
            return true;
        }
        return false;
    }
};

// Some cases play an instance at another speed, or pause one and resume it (a stream of
// their own: the other events are what they were).
// Speed and pause events, each at or after the frame its instance (the k-th to play, in
// the order the plays run) plays.
void paces(Case& c, std::vector<int> playFrames, uint64_t seed) {
    std::stable_sort(playFrames.begin(), playFrames.end());
    Rng r(seed ^ 0x5bd1e9955bd1e995ull);
    if (!r.chance(0.5)) return;
    auto instance = [&] { return static_cast<size_t>(r.below(playFrames.size())); };
    Event speed;
    speed.kind = Event::Kind::Speed;
    size_t k = instance();
    speed.frame = r.between(playFrames[k], c.frames - 1);
    speed.values = {static_cast<float>(k), r.pick(std::vector<float>{0, 0.25f, 0.5f, 2, 3.5f})};
    c.events.push_back(speed);
    if (!r.chance(0.5)) return;
    Event pause;
    pause.kind = Event::Kind::Pause;
    k = instance();
    pause.frame = r.between(playFrames[k], c.frames - 1);
    pause.values = {static_cast<float>(k), 1};
    c.events.push_back(pause);
    Event resume = pause;
    resume.frame = r.between(pause.frame, c.frames);
    resume.values[1] = 0;
    c.events.push_back(resume);
}

}  // namespace

Case generate(uint64_t seed) {
    Rng r(seed);
    Case c;
    c.compareFast = r.chance(0.5);
    Builder b(r.next(), c.compareFast);
    Model m = b.build();
    c.seed = seed;
    c.source = print(m);
    c.frames = r.between(60, 180);
    switch (r.below(4)) {
        case 0: c.dt = 1.0 / 30; break;
        case 1: c.dt = 0; break;  // varied
        default: c.dt = 1.0 / 60; break;
    }
    for (const Trigger& tr : m.triggers) {
        int firings = r.between(1, 3);
        for (int i = 0; i < firings; ++i) {
            Event e;
            e.kind = Event::Kind::Fire;
            e.name = tr.name;
            e.frame = r.between(0, c.frames - 1);
            for (const Param& p : tr.params)
                for (int c = 0; c < (p.ty == Ty::Vec3 ? 3 : 1); ++c)
                    e.values.push_back(static_cast<float>(r.real(-3, 3)));
            c.events.push_back(e);
        }
    }
    for (const Extern& x : m.externs) {
        Event e;
        e.kind = Event::Kind::Set;
        e.name = x.name;
        e.frame = r.between(1, c.frames - 1);
        for (int c = 0; c < (x.ty == Ty::Vec3 ? 3 : 1); ++c) e.values.push_back(static_cast<float>(r.real(x.lo, x.hi)));
        c.events.push_back(e);
    }
    if (m.instanced) {  // (its own draws: a stream of its own, so the other events are what they were)
        Rng plays(seed ^ 0x91a7591a7591a75ull);
        int played = plays.between(1, 3);
        std::vector<int> playFrames;
        for (int i = 0; i < played; ++i) {
            Event e;
            e.kind = Event::Kind::Play;
            e.frame = plays.between(0, c.frames / 2);
            playFrames.push_back(e.frame);
            for (int k = 0; k < 3; ++k) e.values.push_back(static_cast<float>(plays.real(-4, 4)));
            c.events.push_back(e);
        }
        Event end;
        end.kind = plays.chance(0.5) ? Event::Kind::Stop : Event::Kind::Kill;
        end.frame = plays.between(c.frames / 2, c.frames - 1);
        end.values.push_back(static_cast<float>(plays.below(static_cast<size_t>(played))));
        c.events.push_back(end);
        paces(c, playFrames, seed);
    }
    if (r.chance(0.6)) {
        Model edited = m;
        b.edit(edited);
        c.edit = print(edited);
        Event e;
        e.kind = Event::Kind::Reload;
        e.frame = r.between(c.frames / 3, 2 * c.frames / 3);
        c.events.push_back(e);
    }
    std::stable_sort(c.events.begin(), c.events.end(), [](const Event& a, const Event& b) { return a.frame < b.frame; });
    return c;
}

}  // namespace psys::progen
