// The inlined size of functions and equations.
//
// Functions are inlined at every call (the thesis's model: no calls at run time), so a
// function that calls another twice doubles it, and 27 such levels are 2^27 operations: a
// program that checks in no time and then never finishes compiling. Each function's size
// once inlined is counted here, with the calls in its body expanded (memoized: functions
// are not recursive), and what would pass kMaxInlinedOperations is an error where it
// happens: at each function that is too large, or else at each equation that is.
#include <map>
#include <set>

#include <fmt/format.h>

#include "frontend/checker.h"

namespace psys::detail {

using namespace ast;

namespace {

constexpr uint64_t kMaxInlinedOperations = 1'000'000;

uint64_t add(uint64_t a, uint64_t b) { return b > UINT64_MAX - a ? UINT64_MAX : a + b; }

class InlinedSize {
public:
    uint64_t of(const FnDecl& fn) {
        if (auto it = fns_.find(&fn); it != fns_.end()) return it->second;
        fns_[&fn] = 0;  // a recursive call was reported by the checker; count it as nothing
        const FnDecl* outer = current_;
        current_ = &fn;
        uint64_t n = of(*fn.body);
        for (const auto& let : fn.lets) n = add(n, of(*let->value));
        current_ = outer;
        return fns_[&fn] = n;
    }
    // The functions `fn` calls itself.
    const std::set<const FnDecl*>& callees(const FnDecl& fn) { return calls_[&fn]; }

    uint64_t of(const Expr& e) {
        uint64_t n = 1;
        auto sum = [&](const Expr* x) {
            if (x) n = add(n, of(*x));
        };
        switch (e.kind) {
            case ExprKind::Number: case ExprKind::Bool: case ExprKind::Name: break;
            case ExprKind::Call: {
                auto& c = static_cast<const CallExpr&>(e);
                for (const ExprPtr& a : c.args) sum(a.get());
                if (c.fn) {
                    if (current_) calls_[current_].insert(c.fn);
                    n = add(n, of(*c.fn));
                }
                break;
            }
            case ExprKind::Member: sum(static_cast<const MemberExpr&>(e).base.get()); break;
            case ExprKind::Unary: sum(static_cast<const UnaryExpr&>(e).operand.get()); break;
            case ExprKind::Binary:
                sum(static_cast<const BinaryExpr&>(e).lhs.get());
                sum(static_cast<const BinaryExpr&>(e).rhs.get());
                break;
            case ExprKind::Conditional: {
                auto& c = static_cast<const ConditionalExpr&>(e);
                for (const Expr* x : {c.cond.get(), c.thenExpr.get(), c.elseExpr.get()}) sum(x);
                break;
            }
            case ExprKind::Tuple:
                for (const ExprPtr& x : static_cast<const TupleExpr&>(e).elements) sum(x.get());
                break;
            case ExprKind::FollowedBy:
                sum(static_cast<const FollowedByExpr&>(e).init.get());
                sum(static_cast<const FollowedByExpr&>(e).next.get());
                break;
        }
        return n;
    }

private:
    std::map<const FnDecl*, uint64_t> fns_;
    std::map<const FnDecl*, std::set<const FnDecl*>> calls_;
    const FnDecl* current_ = nullptr;
};

std::string operations(uint64_t n) {
    return n == UINT64_MAX ? "more than 10^19 operations" : fmt::format("{} operations", n);
}

void equations(const ObjectDecl& o, InlinedSize& size, DiagnosticEngine& diags) {
    for (const EquationPtr& eq : o.equations)
        if (uint64_t n = size.of(*eq->value); n > kMaxInlinedOperations)
            diags.error(eq->range, fmt::format("equation `{}` is {} once its function calls are inlined, more than the "
                                               "{} an equation may be", eq->names[0], operations(n), kMaxInlinedOperations))
                .report = ProgramReport::InlinedSize;
    for (const auto& child : o.children) equations(*child, size, diags);
}

}  // namespace

void Checker::checkInlinedSize() {
    InlinedSize size;
    std::set<const FnDecl*> tooLarge;
    for (auto& module : program_.modules)
        for (auto& decl : module->decls) {
            if (decl->kind != DeclKind::Fn) continue;
            auto& fn = static_cast<const FnDecl&>(*decl);
            uint64_t n = size.of(fn);
            if (n <= kMaxInlinedOperations) continue;
            tooLarge.insert(&fn);
            // Reported where it starts: a function that is too large only through calling
            // one that is would repeat the error.
            bool throughAnother = false;
            for (const FnDecl* callee : size.callees(fn)) throughAnother |= tooLarge.count(callee) > 0;
            if (throughAnother) continue;
            Diagnostic& d = diags_.error(fn.nameRange, fmt::format("function `{}` is {} once the calls in it are inlined, more "
                                                                   "than the {} a function may be",
                                                                   fn.name, operations(n), kMaxInlinedOperations));
            d.notes.push_back({fn.nameRange, "every call is inlined: a function that calls another twice doubles it"});
            d.report = ProgramReport::InlinedSize;
        }
    if (!tooLarge.empty()) return;  // the functions are the error; their callers would only repeat it
    for (auto& module : program_.modules)
        for (auto& decl : module->decls)
            if (decl->kind == DeclKind::Object) equations(static_cast<const ObjectDecl&>(*decl), size, diags_);
}

}  // namespace psys::detail
