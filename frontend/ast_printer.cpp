// `psysc --emit=ast`: the checked AST as indented text with types on every expression,
// in S-expression form so nesting is unambiguous:  (+:vec3 ipos:vec3 (integrate:vec3 vel:vec3))
#include <sstream>

#include <fmt/format.h>

#include "frontend/builtins.h"
#include "frontend/frontend.h"

namespace psys {
namespace {

using namespace ast;

class AstPrinter {
public:
    explicit AstPrinter(const SourceManager& sources) : sources_(sources) {}

    std::string print(const Program& program) {
        for (auto& module : program.modules) {
            out_ << "module " << module->path << '\n';
            for (auto& decl : module->decls) printDecl(*decl, 1);
        }
        return out_.str();
    }

private:
    std::string at(SourceRange r) const {
        if (!r.valid()) return "";
        LineColumn lc = sources_.file(r.file).lineColumn(r.begin);
        return fmt::format("  @{}:{}", lc.line, lc.column);
    }
    void line(int depth, const std::string& text, SourceRange r = {}) {
        out_ << std::string(static_cast<size_t>(depth) * 2, ' ') << text << at(r) << '\n';
    }

    static std::string params(const std::vector<Param>& ps) {
        std::string s;
        for (auto& p : ps) s += (s.empty() ? "" : ", ") + p.name + ": " + p.type.type.str();
        return s;
    }

    std::string expr(const Expr& e) {
        std::string t = ":" + e.type.str();
        switch (e.kind) {
            case ExprKind::Number: return static_cast<const NumberExpr&>(e).spelling;
            case ExprKind::Bool: return static_cast<const BoolExpr&>(e).value ? "true" : "false";
            case ExprKind::Name: return static_cast<const NameExpr&>(e).name + t;
            case ExprKind::Call: {
                auto& c = static_cast<const CallExpr&>(e);
                std::string s = "(" + c.callee + t;
                for (auto& a : c.args) s += " " + expr(*a);
                return s + ")";
            }
            case ExprKind::Member: {
                auto& m = static_cast<const MemberExpr&>(e);
                if (m.parent) return fmt::format("(parent {} {}){}", m.parent->name, m.member, t);
                return fmt::format("(.{}{} {})", m.member, t, expr(*m.base));
            }
            case ExprKind::Unary: {
                auto& u = static_cast<const UnaryExpr&>(e);
                return fmt::format("({}{} {})", u.op == UnaryOp::Neg ? "neg" : spelling(u.op), t, expr(*u.operand));
            }
            case ExprKind::Binary: {
                auto& b = static_cast<const BinaryExpr&>(e);
                return fmt::format("({}{} {} {})", spelling(b.op), t, expr(*b.lhs), expr(*b.rhs));
            }
            case ExprKind::Conditional: {
                auto& c = static_cast<const ConditionalExpr&>(e);
                return fmt::format("(select{} {} {} {})", t, expr(*c.cond), expr(*c.thenExpr), expr(*c.elseExpr));
            }
            case ExprKind::Tuple: {
                std::string s = "(tuple" + t;
                for (auto& el : static_cast<const TupleExpr&>(e).elements) s += " " + expr(*el);
                return s + ")";
            }
            case ExprKind::FollowedBy: {
                auto& f = static_cast<const FollowedByExpr&>(e);
                return fmt::format("(->{} {} {})", t, expr(*f.init), expr(*f.next));
            }
        }
        return "?";
    }

    void attribute(const Attribute& a, int depth) {
        std::string s = "@" + a.name + "(";
        for (size_t i = 0; i < a.args.size(); ++i) s += (i ? ", " : "") + expr(*a.args[i]);
        line(depth, s + ")", a.range);
    }

    void command(const Command& c, int depth) {
        switch (c.kind) {
            case CommandKind::Draw: {
                std::string s(core::drawKindName(c.draw));
                for (auto& a : c.args) s += " " + expr(*a);
                line(depth, s, c.range);
                break;
            }
            case CommandKind::Kill: line(depth, "kill when " + (c.cond ? expr(*c.cond) : "true"), c.range); break;
            case CommandKind::Emit: {
                std::string s = "emit " + c.target + "(";
                for (size_t i = 0; i < c.args.size(); ++i) s += (i ? ", " : "") + expr(*c.args[i]);
                s += ")";
                if (c.rate) s += " at " + expr(*c.rate) + " per second";
                if (c.count) s += " count " + expr(*c.count);
                if (!c.rate) s += " once";
                line(depth, s, c.range);
                break;
            }
            case CommandKind::When:
                line(depth, "when " + expr(*c.cond), c.range);
                for (auto& inner : c.body) command(*inner, depth + 1);
                break;
            case CommandKind::On:
                line(depth, "on " + c.event, c.range);
                for (auto& inner : c.body) command(*inner, depth + 1);
                break;
            case CommandKind::Notify: {
                std::string s = "notify \"" + c.event + "\"(";
                for (size_t i = 0; i < c.args.size(); ++i) s += (i ? ", " : "") + expr(*c.args[i]);
                line(depth, s + ")", c.range);
                break;
            }
        }
    }

    void object(const ObjectDecl& o, int depth) {
        for (auto& a : o.attributes) attribute(a, depth);
        line(depth, fmt::format("object {}({})", o.name, params(o.params)), o.nameRange);
        for (auto& eq : o.equations) {
            std::string names;
            for (size_t i = 0; i < eq->names.size(); ++i)
                names += (i ? ", " : "") + eq->names[i] + ": " + eq->types[i].str();
            if (eq->isTuple()) names = "(" + names + ")";
            line(depth + 1, "equation " + names + " = " + expr(*eq->value), eq->range);
        }
        for (auto& c : o.commands) command(*c, depth + 1);
        for (auto& child : o.children) object(*child, depth + 1);
    }

    void printDecl(const Decl& d, int depth) {
        switch (d.kind) {
            case DeclKind::Import: {
                auto& i = static_cast<const ImportDecl&>(d);
                line(depth, fmt::format("import \"{}\"", i.path), d.range);
                break;
            }
            case DeclKind::Attribute: attribute(static_cast<const FileAttributeDecl&>(d).attribute, depth); break;
            case DeclKind::Const: {
                auto& c = static_cast<const ConstDecl&>(d);
                line(depth, fmt::format("const {}: {} = {}", c.name, c.type.str(), expr(*c.value)), d.nameRange);
                break;
            }
            case DeclKind::Fn: {
                auto& f = static_cast<const FnDecl&>(d);
                line(depth, fmt::format("fn {}({}) -> {}", f.name, params(f.params), f.resultType.str()), d.nameRange);
                for (auto& l : f.lets) line(depth + 1, fmt::format("let {}: {} = {}", l->name, l->type.str(), expr(*l->value)));
                line(depth + 1, "= " + expr(*f.body));
                break;
            }
            case DeclKind::Extern: {
                auto& e = static_cast<const ExternDecl&>(d);
                std::string s = fmt::format("extern {}: {}", e.name, e.type.type.str());
                if (e.defaultValue) s += " = " + expr(*e.defaultValue);
                if (e.rangeLow) s += " range(" + expr(*e.rangeLow) + ", " + expr(*e.rangeHigh) + ")";
                line(depth, s, d.nameRange);
                break;
            }
            case DeclKind::Trigger: {
                auto& t = static_cast<const TriggerDecl&>(d);
                line(depth, fmt::format("trigger {}({})", t.name, params(t.params)), d.nameRange);
                for (auto& c : t.commands) command(*c, depth + 1);
                break;
            }
            case DeclKind::Object: object(static_cast<const ObjectDecl&>(d), depth); break;
            case DeclKind::Spawn: {
                auto& s = static_cast<const SpawnDecl&>(d);
                std::string text = "spawn " + s.name + "(";
                for (size_t i = 0; i < s.args.size(); ++i) text += (i ? ", " : "") + expr(*s.args[i]);
                line(depth, text + ")", d.range);
                break;
            }
        }
    }

    const SourceManager& sources_;
    std::ostringstream out_;
};

}  // namespace

std::string printAst(const Program& program, const SourceManager& sources) {
    return AstPrinter(sources).print(program);
}

}  // namespace psys
