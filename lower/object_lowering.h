// Internal to lower/: the lowering of one object (or trigger, or the start) to a kernel.
// lower.cpp drives it per object and lowers commands; lower_expr.cpp holds the evaluation
// order and expressions; lower_calls.cpp inlines functions and expands built-ins.
#pragma once

#include <functional>
#include <map>
#include <set>
#include <tuple>
#include <vector>

#include "frontend/ast.h"
#include "frontend/source.h"
#include "ir/ir.h"

namespace psys::lower::detail {

// Written against the IR's names: where the AST (or the front end's psys::Type) has one
// of the same spelling, the IR's is meant.
using namespace ast;
using namespace ir;
using ir::Module;
using ir::Param;
using ir::Type;

// Source ranges as IR locations: file, line, column and the length on that line.
class Locator {
public:
    explicit Locator(const SourceManager& sources) : sources_(sources) {}
    Loc operator()(SourceRange r) const {
        if (!r.valid() || r.file >= sources_.count()) return {};
        const SourceFile& f = sources_.file(r.file);
        LineColumn start = f.lineColumn(r.begin), end = f.lineColumn(r.end);
        uint32_t length = end.line == start.line && r.end > r.begin ? r.end - r.begin : 1;
        return {r.file, start.line, start.column, length};
    }

private:
    const SourceManager& sources_;
};

inline Type irType(const psys::Type& t) {
    if (t.isBool()) return Type::boolean();
    return Type::vec(std::max(1, t.width()));
}

// A lowered expression: one value, or several for a tuple.
using Values = std::vector<ValueId>;

struct FnFrame {
    const FnDecl* fn;
    std::vector<Values> params;
    std::map<const LetStmt*, Values> lets;
};

class ObjectLowering {
public:
    ObjectLowering(const Module& module, const Locator& locate, Kernel& kernel, Object* object, const ObjectDecl* decl,
                   const TriggerDecl* trigger, int& siteCounter)
        : module_(module), locate_(locate), k_(kernel), object_(object), decl_(decl), trigger_(trigger),
          site_(siteCounter) {}

    Loc locate(SourceRange r) const { return locate_(r); }

    // The object's equations, in evaluation order.
    void lowerEquations() {
        for (size_t i = 0; i < decl_->params.size(); ++i) {
            LocScope at(k_, locate_(decl_->params[i].nameRange));
            k_.equations[decl_->params[i].name] = input(Op::Param, irType(decl_->params[i].type.type), static_cast<int>(i));
        }
        std::vector<const Equation*> order = evaluationOrder();
        for (const Equation* eq : order) {
            current_ = eq;
            LocScope at(k_, locate_(eq->range));
            Values v = lower(*eq->value);
            for (size_t i = 0; i < eq->names.size() && i < v.size(); ++i) {
                name(v[i], eq->names[i]);
                k_.equations[eq->names[i]] = v[i];
            }
            values_[eq] = v;
        }
        current_ = nullptr;
        for (auto& [recur, target] : pendingRecurs_) {
            ValueId value = values_.at(target.first).at(target.second);
            k_.mutableAt(recur).operands = {value};
        }
        flushDeferred();
    }

    // `prev(e)` reads a slot; `e` itself is needed only for the slot's next value, at the
    // end of the update, when every equation has its current value. So `e` is lowered
    // last, and what it reads is this update's value even where it refers forward.
    void flushDeferred() {
        while (!deferred_.empty()) {
            auto [prevs, arg, frames] = std::move(deferred_.back());
            deferred_.pop_back();
            auto saved = std::move(frames_);
            frames_ = std::move(frames);
            Values v = lower(*arg);
            frames_ = std::move(saved);
            for (size_t i = 0; i < prevs.size(); ++i) k_.mutableAt(prevs[i]).operands = {v.at(i)};
        }
    }

    Values lower(const Expr& e);
    ValueId lowerOne(const Expr& e) { return lower(e).at(0); }

    // Adds `value` as `kind` under the conditions of the enclosing `when`s.
    ValueId guard(const std::vector<ValueId>& conditions) {
        ValueId all = k_.boolean(true);
        for (ValueId c : conditions) all = k_.op(Op::And, Type::boolean(), {all, c});
        return all;
    }

private:
    void name(ValueId v, const std::string& n) {
        Inst& inst = k_.mutableAt(v);
        if (inst.name.empty() && !isLeaf(inst.op)) inst.name = n;
    }

    std::vector<const Equation*> evaluationOrder();
    Values lowerName(const NameExpr& n);
    Values lowerCall(const CallExpr& c);
    ValueId broadcastTo(ValueId v, Type t);
    ValueId arith(Op op, ValueId a, ValueId b);
    ValueId scalarConst(float x, Type t) {
        if (t.width == 1) return k_.scalar(x);
        return k_.constant(t, {x, x, x, x});
    }
    ValueId extract(ValueId v, int i) {
        Inst inst;
        inst.op = Op::Extract;
        inst.type = Type::f32();
        inst.operands = {v};
        inst.attr = i;
        return k_.add(std::move(inst));
    }
    ValueId shuffle(ValueId v, std::vector<uint8_t> lanes) {
        Inst inst;
        inst.op = Op::Shuffle;
        inst.type = Type::vec(static_cast<int>(lanes.size()));
        inst.operands = {v};
        inst.lanes = std::move(lanes);
        return k_.add(std::move(inst));
    }
    ValueId input(Op op, Type t, int attr = 0, int attr2 = 0) {
        Inst inst;
        inst.op = op;
        inst.type = t;
        inst.attr = attr;
        inst.attr2 = attr2;
        return k_.add(std::move(inst));
    }
    ValueId parentRead(const MemberExpr& m);
    ValueId lowerNear(const CallExpr& c);
    ValueId neighbourRead(bool other, const std::string& member, Type t);

public:
    // The instance this object (or trigger, or start) belongs to, in an instanced program:
    // its hidden last parameter (core/instances.h).
    ValueId instance() {
        if (object_) return input(Op::Param, Type::f32(), static_cast<int>(object_->params.size()) - 1);
        return input(Op::TriggerParam, Type::f32(), trigger_ ? static_cast<int>(trigger_->params.size()) : 0);
    }
    // Value `value` of that instance's record.
    ValueId instanceRecord(int value) {
        return k_.add(Inst::make(Op::Instance, Type::vec(4), {instance()}, value, static_cast<int>(module_.externs.size())));
    }
    // A flag of the record's (core/instances.h: kInstanceEmitting, …): the w lane of value `flag`.
    ValueId instanceFlag(int flag) { return extract(instanceRecord(flag), 3); }
    // `instance.pos`, … (frontend/builtins.h, instanceMembers).
    ValueId instanceMember(int member);

    // Object types' names in the IR (nested ones qualified): what a fold names its type by.
    std::function<std::string(const ObjectDecl*)> qualify;
    // Lowering a fold's term into a pair kernel: the object's names read its exports.
    bool pair_ = false;
    // While lowering emit arguments: random draws there are one per created object.
    bool perChild_ = false;
    // A temporal op or random draw: its own call site (a trail's history is built of them).
    ValueId temporal(Op op, Type t, std::vector<ValueId> operands) {
        Inst inst;
        inst.op = op;
        inst.type = t;
        inst.operands = std::move(operands);
        inst.attr = site_++;
        if ((op == Op::Rand || op == Op::NRand) && (perChild_ || !decl_)) inst.attr2 = 1;
        return k_.addUnique(std::move(inst));
    }

private:

    const Module& module_;
    const Locator& locate_;
    Kernel& k_;
    Object* object_;
    const ObjectDecl* decl_;
    const TriggerDecl* trigger_;
    int& site_;
    std::map<const Equation*, Values> values_;
    std::vector<std::pair<ValueId, std::pair<const Equation*, size_t>>> pendingRecurs_;
    const Equation* current_ = nullptr;
    std::vector<FnFrame> frames_;
    std::vector<std::tuple<Values, const Expr*, std::vector<FnFrame>>> deferred_;  // prev: a slot per element
};

}  // namespace psys::lower::detail
