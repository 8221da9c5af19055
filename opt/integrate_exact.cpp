// The exact method: each integral in closed form over the step.
//
// Within one update (τ from 0 to dt) every value the derivatives read is written as a sum
// of terms  coef·τᵖ  (a polynomial in τ: what is fixed over the step, the age and time
// as (age − dt) + τ, a constant acceleration's velocity) and  coef·τᵖ·φp(k·τ)  (what a
// linear decay at rate k produces; opt/phi.h). Integrating such a sum term by term stays
// in the family:
//
//   ∫₀ᵗ c·τᵖ dτ = c/(p+1)·tᵖ⁺¹             ∫₀ᵗ c·τᵖ·φp(kτ) dτ = c·tᵖ⁺¹·φp+1(kt)
//
// and an integral whose derivative is g(τ) − k·y, g a polynomial Σ gp·τᵖ, is
//
//   y(t) = y0·φ0(kt) + Σ gp·p!·tᵖ⁺¹·φp+1(kt).
//
// The integrals are solved one after another in dependency order; each value at the end
// of the update is its sum at τ = dt. Where everything the derivatives read is fixed at
// creation, the same sums are taken over the object's whole life instead (from 0 at
// creation to τ = age): no state, and no rounding carried from one step to the next.
// That covers polynomials in age (projectiles, any constant force), linear drag with
// constant forcing, and chains of them (the position of a particle under drag). A derivative outside the family — a coupled system such as a
// spring, a decay rate that changes within the step, sin of the age — is an error at the
// integral, never a quiet fallback to another method.
#include <fmt/format.h>

#include <functional>
#include <set>

#include "opt/integrate_methods.h"
#include "opt/phi.h"
#include "opt/rewrite.h"

namespace psys::opt {

using namespace ir;

namespace {

constexpr int kMaxDegree = 8;

struct Term {
    ValueId coef;
    int power = 0;
    std::optional<ValueId> rate;  // coef·τᵖ·φp(rate·τ); none: coef·τᵖ
};

// A value over the step: Σ terms + self·y, y the integral being solved.
struct Sum {
    Type type;
    std::vector<Term> terms;
    std::optional<ValueId> self;
    bool fixed() const { return !self && terms.size() == 1 && terms[0].power == 0 && !terms[0].rate; }
    bool polynomial() const {
        for (const Term& t : terms)
            if (t.rate) return false;
        return !self;
    }
};

struct NoClosedForm {
    std::string why;
    ir::Loc at{};  // the part of the source that has none, where it is not the equation as a whole
};
// A derivative reads something that may change after creation: solve step by step.
struct NotFixedAtCreation {};

// The name a .psys program calls an operation by (`sin`), or "" where it has none.
std::string_view builtinName(Op op) {
    std::string_view signature = opInfo(op).spelling.builtin;
    return signature.substr(0, signature.find('('));
}

class ClosedForm {
public:
    ClosedForm(StepBuilder& b, const std::vector<std::string>& names) : b_(b), k_(b.to()), names_(names) {}

    // From creation where every value the derivatives read is fixed at creation (constants
    // and parameters): then each integral is a function of the age alone, with no state
    // and no rounding carried from step to step. Otherwise over each step, from the state.
    std::vector<ValueId> solve() {
        try {
            fromCreation_ = true;
            return solveAll();
        } catch (const NotFixedAtCreation&) {
            fromCreation_ = false;
            solved_.clear();
            return solveAll();
        }
    }

    size_t failedAt() const { return current_; }

private:
    std::vector<ValueId> solveAll() {
        for (size_t j : order()) {
            current_ = j;
            memo_.clear();  // `self` meant the previous integral
            solved_[j] = integral(j, of(b_.derivative(j)));
        }
        std::vector<ValueId> out;
        for (size_t j = 0; j < b_.size(); ++j) {
            LocScope at(k_, b_.loc(j));
            out.push_back(valueAtEnd(solved_.at(j)));
        }
        return out;
    }

    // τ at the end of the update: the step's length, or from creation the age.
    ValueId span() { return fromCreation_ ? k_.add(Inst::make(Op::Age, Type::f32())) : b_.dt(); }
    // Integral j at τ = 0.
    ValueId start(size_t j) { return fromCreation_ ? k_.constant(b_.type(j), {0, 0, 0, 0}) : b_.start(j); }
    // The integrals in an order where each derivative reads only integrals before it.
    std::vector<size_t> order() {
        size_t n = b_.size();
        std::vector<std::set<size_t>> reads(n);
        for (size_t j = 0; j < n; ++j) {
            std::vector<ValueId> work = {b_.derivative(j)};
            std::set<ValueId> seen;
            while (!work.empty()) {
                ValueId v = work.back();
                work.pop_back();
                if (!seen.insert(v).second || !b_.dependent(v)) continue;
                const Inst& i = b_.from().at(v);
                if (i.op == Op::Integrate) {
                    for (size_t x = 0; x < n; ++x)
                        if (b_.integral(x) == v && x != j) reads[j].insert(x);
                    continue;
                }
                for (ValueId o : i.operands) work.push_back(o);
            }
        }
        std::vector<size_t> out;
        std::vector<int> state(n, 0);  // 0: to visit, 1: on the path, 2: done
        std::function<void(size_t)> visit = [&](size_t j) {
            if (state[j] == 2) return;
            current_ = j;
            if (state[j] == 1) throw NoClosedForm{"it is part of a coupled system of integrals"};
            state[j] = 1;
            for (size_t x : reads[j]) {
                if (state[x] == 1) {
                    current_ = j;
                    throw NoClosedForm{fmt::format("its derivative depends on `{}`, whose derivative depends on it "
                                                   "(a coupled system, such as a spring)", names_[x])};
                }
                visit(x);
            }
            state[j] = 2;
            out.push_back(j);
        };
        for (size_t j = 0; j < n; ++j) visit(j);
        return out;
    }

    Sum fixed(ValueId v) { return {k_.at(v).type, {{v, 0, std::nullopt}}, std::nullopt}; }
    ValueId one(Type t) { return k_.constant(t, {1, 1, 1, 1}); }

    // `old` over the step.
    Sum of(ValueId old) {
        if (!b_.dependent(old)) {
            if (fromCreation_ && !b_.fixedAtCreation(old)) throw NotFixedAtCreation{};
            return fixed(b_.final(old));
        }
        if (auto it = memo_.find(old); it != memo_.end()) return it->second;
        Sum s = compute(old);
        return memo_[old] = s;
    }

    Sum compute(ValueId old) {
        const Inst& i = b_.from().at(old);
        auto op = [&](size_t n) { return of(i.operands[n]); };
        switch (i.op) {
            case Op::Integrate:
                for (size_t x = 0; x < b_.size(); ++x) {
                    if (b_.integral(x) != old) continue;
                    if (x == current_) return {i.type, {}, one(i.type)};
                    return solved_.at(x);
                }
                break;
            case Op::Age: case Op::Time: {
                if (fromCreation_ && i.op == Op::Time) throw NotFixedAtCreation{};
                ValueId start = fromCreation_ ? k_.scalar(0) : b_.clockAt(i.op, b_.pointAt(0, {}));
                return {i.type, {{start, 0, std::nullopt}, {one(i.type), 1, std::nullopt}}, std::nullopt};
            }
            case Op::Recur: return op(0);
            case Op::Add: return plus(op(0), op(1), false);
            case Op::Sub: return plus(op(0), op(1), true);
            case Op::Neg: return scaled(op(0), i.type, [&](ValueId c) { return k_.op(Op::Neg, i.type, {c}); });
            case Op::Mul: return times(op(0), op(1));
            case Op::Div: {
                Sum d = op(1);
                if (!d.fixed()) throw NoClosedForm{"its derivative divides by a value that changes within the step"};
                ValueId by = d.terms[0].coef;
                return scaled(op(0), i.type, [&](ValueId c) { return k_.op(Op::Div, i.type, {c, by}); });
            }
            case Op::Splat: return scaled(op(0), i.type, [&](ValueId c) { return k_.op(Op::Splat, i.type, {c}); });
            case Op::Extract: return extract(op(0), i.attr);
            case Op::Compose: return compose(i);
            default: break;
        }
        // An operation the user wrote by name is named; one the compiler made (`select`, from
        // `derive`, `if` or a comparison) is shown where it comes from instead.
        if (std::string_view fn = builtinName(i.op); !fn.empty())
            throw NoClosedForm{fmt::format("its derivative applies `{}` to a value that changes within the step", fn)};
        throw NoClosedForm{"this part of its derivative changes within the step in a way the exact method cannot follow", i.loc};
    }

    // Each coefficient (and self) through `f`, giving a value of type `t`; rates stay.
    Sum scaled(const Sum& s, Type t, const std::function<ValueId(ValueId)>& f) {
        Sum out{t, {}, std::nullopt};
        for (const Term& t : s.terms) out.terms.push_back({f(t.coef), t.power, t.rate});
        if (s.self) out.self = f(*s.self);
        return out;
    }

    Sum plus(const Sum& a, const Sum& b, bool minus) {
        Sum out = a;
        for (const Term& t : b.terms) {
            ValueId c = minus ? k_.op(Op::Neg, k_.at(t.coef).type, {t.coef}) : t.coef;
            add(out, {c, t.power, t.rate});
        }
        if (b.self) {
            ValueId s = minus ? k_.op(Op::Neg, k_.at(*b.self).type, {*b.self}) : *b.self;
            out.self = out.self ? k_.op(Op::Add, out.type, {*out.self, s}) : s;
        }
        return out;
    }

    // Adds a term, merging it with one of the same power and rate.
    void add(Sum& s, const Term& t) {
        for (Term& e : s.terms)
            if (e.power == t.power && e.rate == t.rate) {
                e.coef = k_.op(Op::Add, k_.at(e.coef).type, {e.coef, t.coef});
                return;
            }
        s.terms.push_back(t);
    }

    Sum times(const Sum& a, const Sum& b) {
        if (a.fixed() || b.fixed()) {
            const Sum& f = a.fixed() ? a : b;
            ValueId by = f.terms[0].coef;
            return scaled(a.fixed() ? b : a, a.type, [&](ValueId c) { return k_.op(Op::Mul, a.type, {by, c}); });
        }
        if (!a.polynomial() || !b.polynomial())
            throw NoClosedForm{"its derivative multiplies two values that change within the step, one of them "
                               "decaying or the integral itself"};
        Sum out{a.type, {}, std::nullopt};
        for (const Term& x : a.terms)
            for (const Term& y : b.terms) {
                if (x.power + y.power > kMaxDegree)
                    throw NoClosedForm{fmt::format("its derivative is a polynomial of degree above {}", kMaxDegree)};
                add(out, {k_.op(Op::Mul, a.type, {x.coef, y.coef}), x.power + y.power, std::nullopt});
            }
        return out;
    }

    Sum extract(const Sum& s, int lane) {
        auto pick = [&](ValueId v) {
            if (k_.at(v).type.width == 1) return v;
            if (k_.at(v).op == Op::Splat) return k_.at(v).operands[0];
            return k_.op(Op::Extract, Type::f32(), {v}, lane);
        };
        Sum out{Type::f32(), {}, std::nullopt};
        for (const Term& t : s.terms)
            out.terms.push_back({pick(t.coef), t.power, t.rate ? std::optional<ValueId>(pick(*t.rate)) : std::nullopt});
        if (s.self) throw NoClosedForm{"its derivative reads one component of the integral itself"};
        return out;
    }

    // Each component's terms, placed in its lanes of the vector (zeros elsewhere).
    Sum compose(const Inst& i) {
        Sum out{i.type, {}, std::nullopt};
        for (size_t n = 0; n < i.operands.size(); ++n) {
            Sum part = of(i.operands[n]);
            if (part.self) throw NoClosedForm{"its derivative rearranges the components of the integral itself"};
            for (const Term& t : part.terms) {
                if (t.rate && k_.at(*t.rate).type.width != 1)
                    throw NoClosedForm{"its derivative rearranges the components of a decaying vector"};
                std::vector<ValueId> lanes;
                for (size_t m = 0; m < i.operands.size(); ++m)
                    lanes.push_back(m == n ? t.coef : k_.constant(b_.from().at(i.operands[m]).type, {0, 0, 0, 0}));
                add(out, {k_.op(Op::Compose, i.type, lanes), t.power, t.rate});
            }
        }
        return out;
    }

    // Integral j over the step, from its derivative.
    Sum integral(size_t j, const Sum& derivative) {
        Type t = b_.type(j);
        Sum out{t, {}, std::nullopt};
        if (!derivative.self) {
            out.terms.push_back({start(j), 0, std::nullopt});
            for (const Term& d : derivative.terms) {
                // ∫ c·τᵖ = c/(p+1)·τᵖ⁺¹;  ∫ c·τᵖ·φp(kτ) = c·τᵖ⁺¹·φp+1(kτ).
                ValueId c = d.coef;
                if (!d.rate && d.power > 0) c = k_.op(Op::Div, t, {d.coef, uniformConst(t, static_cast<float>(d.power + 1))});
                add(out, {c, d.power + 1, d.rate});
            }
            return out;
        }
        // y' = g − k·y with k = −self.
        for (const Term& d : derivative.terms)
            if (d.rate)
                throw NoClosedForm{"it decays while driven by another decaying value"};
        ValueId rate = k_.op(Op::Neg, t, {*derivative.self});
        out.terms.push_back({start(j), 0, rate});
        for (const Term& d : derivative.terms) {
            double f = 1;
            for (int p = 2; p <= d.power; ++p) f *= p;
            ValueId c = f == 1 ? d.coef : k_.op(Op::Mul, t, {d.coef, uniformConst(t, static_cast<float>(f))});
            add(out, {c, d.power + 1, rate});
        }
        return out;
    }

    ValueId uniformConst(Type t, float x) { return k_.constant(t, {x, x, x, x}); }

    // Σ coef·τᵖ(·φp(rate·τ)) at the end of the update.
    ValueId valueAtEnd(const Sum& s) {
        ValueId total = 0;
        bool any = false;
        for (const Term& t : s.terms) {
            ValueId v = t.coef;
            if (t.rate) v = b_.mul(v, phi(k_, t.power, b_.mul(*t.rate, span())));
            if (t.power > 0) v = b_.mul(power(t.power), v);
            total = any ? b_.add(total, v) : v;
            any = true;
        }
        return any ? total : k_.constant(s.type, {0, 0, 0, 0});
    }

    ValueId power(int p) {
        ValueId v = span();
        for (int i = 1; i < p; ++i) v = k_.op(Op::Mul, Type::f32(), {v, span()});
        return v;
    }

    StepBuilder& b_;
    Kernel& k_;
    const std::vector<std::string>& names_;
    size_t current_ = 0;
    bool fromCreation_ = false;
    std::map<size_t, Sum> solved_;
    std::map<ValueId, Sum> memo_;
};

}  // namespace

std::optional<std::vector<ValueId>> closedForm(StepBuilder& b, const std::string& object,
                                               const std::vector<std::string>& names, PassErrors& errors) {
    ClosedForm form(b, names);
    try {
        return form.solve();
    } catch (const NoClosedForm& e) {
        size_t j = form.failedAt();
        errors.error(e.at.valid() ? e.at : b.loc(j), fmt::format("object {}: @integrator(exact) has no closed form for `{}`: {}; use rk4 "
                                           "(or another method) for this object",
                                           object, names[j], e.why));
        return std::nullopt;
    }
}

}  // namespace psys::opt
