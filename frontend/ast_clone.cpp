// Copies of declarations as the parser built them, moved to another place in a file.
//
// The language server parses an edited file by top-level declaration (frontend/parse.h,
// ParseCache): a declaration whose text did not change is not parsed again but copied
// from its last parse, its ranges moved to where it now starts. A copy is needed because
// the checker annotates the tree in place. Only what the parser sets is copied (the
// checker's annotations of a parsed tree are their defaults); the one link the parser
// makes, a nested object's `parent`, points into the copy.
#include "frontend/ast.h"

namespace psys::ast {

namespace {

class Cloner {
public:
    Cloner(int file, int64_t shift) : file_(file), shift_(shift) {}

    SourceRange at(SourceRange r) const {
        if (!r.valid()) return r;
        return {file_, static_cast<uint32_t>(r.begin + shift_), static_cast<uint32_t>(r.end + shift_)};
    }

    ExprPtr expr(const ExprPtr& e) {
        if (!e) return nullptr;
        ExprPtr out = copy(*e);
        out->type = e->type;
        return out;
    }
    std::vector<ExprPtr> exprs(const std::vector<ExprPtr>& es) {
        std::vector<ExprPtr> out;
        out.reserve(es.size());
        for (const ExprPtr& e : es) out.push_back(expr(e));
        return out;
    }
    TypeAnnotation annotation(const TypeAnnotation& t) const { return {t.type, at(t.range), t.spelling}; }
    std::optional<TypeAnnotation> annotation(const std::optional<TypeAnnotation>& t) const {
        if (!t) return std::nullopt;
        return annotation(*t);
    }
    std::vector<Param> params(const std::vector<Param>& ps) const {
        std::vector<Param> out;
        for (const Param& p : ps) out.push_back({p.name, at(p.nameRange), annotation(p.type)});
        return out;
    }
    Attribute attribute(const Attribute& a) {
        Attribute out;
        out.name = a.name, out.range = at(a.range), out.nameRange = at(a.nameRange);
        out.text = a.text, out.textRange = at(a.textRange);
        out.args = exprs(a.args);
        return out;
    }
    CommandPtr command(const Command& c) {
        auto out = std::make_unique<Command>();
        out->kind = c.kind, out->range = at(c.range), out->keywordRange = at(c.keywordRange);
        out->args = exprs(c.args);
        out->draw = c.draw;
        out->cond = expr(c.cond);
        out->target = c.target, out->targetRange = at(c.targetRange);
        out->rate = expr(c.rate), out->count = expr(c.count);
        out->body = commands(c.body);
        out->event = c.event, out->eventRange = at(c.eventRange);
        return out;
    }
    std::vector<CommandPtr> commands(const std::vector<CommandPtr>& cs) {
        std::vector<CommandPtr> out;
        for (const CommandPtr& c : cs) out.push_back(command(*c));
        return out;
    }
    std::unique_ptr<ObjectDecl> object(const ObjectDecl& o, const ObjectDecl* parent) {
        auto out = std::make_unique<ObjectDecl>(at(o.range));
        base(o, *out);
        for (const Attribute& a : o.attributes) out->attributes.push_back(attribute(a));
        out->params = params(o.params);
        for (const EquationPtr& eq : o.equations) {
            auto e = std::make_unique<Equation>();
            e->names = eq->names;
            for (SourceRange r : eq->nameRanges) e->nameRanges.push_back(at(r));
            e->annotation = annotation(eq->annotation);
            e->value = expr(eq->value);
            e->range = at(eq->range);
            out->equations.push_back(std::move(e));
        }
        out->commands = commands(o.commands);
        for (const auto& child : o.children) out->children.push_back(object(*child, out.get()));
        out->parent = parent;
        return out;
    }
    DeclPtr decl(const Decl& d);

private:
    ExprPtr copy(const Expr& e);
    void base(const Decl& from, Decl& to) const {
        to.name = from.name;
        to.nameRange = at(from.nameRange);
    }

    int file_;
    int64_t shift_;
};

ExprPtr Cloner::copy(const Expr& e) {
    SourceRange r = at(e.range);
    switch (e.kind) {
        case ExprKind::Number: {
            const auto& n = static_cast<const NumberExpr&>(e);
            return std::make_unique<NumberExpr>(r, n.value, n.spelling);
        }
        case ExprKind::Bool: return std::make_unique<BoolExpr>(r, static_cast<const BoolExpr&>(e).value);
        case ExprKind::Name: return std::make_unique<NameExpr>(r, static_cast<const NameExpr&>(e).name);
        case ExprKind::Call: {
            const auto& c = static_cast<const CallExpr&>(e);
            auto out = std::make_unique<CallExpr>(r, c.callee, at(c.calleeRange));
            out->args = exprs(c.args);
            return out;
        }
        case ExprKind::Member: {
            const auto& m = static_cast<const MemberExpr&>(e);
            return std::make_unique<MemberExpr>(r, expr(m.base), m.member, at(m.memberRange));
        }
        case ExprKind::Unary: {
            const auto& u = static_cast<const UnaryExpr&>(e);
            return std::make_unique<UnaryExpr>(r, u.op, expr(u.operand));
        }
        case ExprKind::Binary: {
            const auto& b = static_cast<const BinaryExpr&>(e);
            return std::make_unique<BinaryExpr>(r, b.op, at(b.opRange), expr(b.lhs), expr(b.rhs));
        }
        case ExprKind::Conditional: {
            const auto& c = static_cast<const ConditionalExpr&>(e);
            return std::make_unique<ConditionalExpr>(r, expr(c.cond), expr(c.thenExpr), expr(c.elseExpr));
        }
        case ExprKind::Tuple: {
            auto out = std::make_unique<TupleExpr>(r);
            out->elements = exprs(static_cast<const TupleExpr&>(e).elements);
            return out;
        }
        case ExprKind::FollowedBy: {
            const auto& f = static_cast<const FollowedByExpr&>(e);
            return std::make_unique<FollowedByExpr>(r, expr(f.init), expr(f.next));
        }
    }
    return nullptr;
}

DeclPtr Cloner::decl(const Decl& d) {
    SourceRange r = at(d.range);
    DeclPtr out;
    switch (d.kind) {
        case DeclKind::Import: {
            const auto& i = static_cast<const ImportDecl&>(d);
            auto o = std::make_unique<ImportDecl>(r);
            o->path = i.path, o->pathRange = at(i.pathRange);
            out = std::move(o);
            break;
        }
        case DeclKind::Attribute: {
            auto o = std::make_unique<FileAttributeDecl>(r);
            o->attribute = attribute(static_cast<const FileAttributeDecl&>(d).attribute);
            out = std::move(o);
            break;
        }
        case DeclKind::Const: {
            const auto& c = static_cast<const ConstDecl&>(d);
            auto o = std::make_unique<ConstDecl>(r);
            o->annotation = annotation(c.annotation);
            o->value = expr(c.value);
            out = std::move(o);
            break;
        }
        case DeclKind::Fn: {
            const auto& f = static_cast<const FnDecl&>(d);
            auto o = std::make_unique<FnDecl>(r);
            o->params = params(f.params);
            o->returnType = annotation(f.returnType);
            for (const auto& let : f.lets) {
                auto l = std::make_unique<LetStmt>();
                l->name = let->name, l->nameRange = at(let->nameRange);
                l->annotation = annotation(let->annotation);
                l->value = expr(let->value);
                o->lets.push_back(std::move(l));
            }
            o->body = expr(f.body);
            out = std::move(o);
            break;
        }
        case DeclKind::Extern: {
            const auto& x = static_cast<const ExternDecl&>(d);
            auto o = std::make_unique<ExternDecl>(r);
            o->type = annotation(x.type);
            o->defaultValue = expr(x.defaultValue), o->rangeLow = expr(x.rangeLow), o->rangeHigh = expr(x.rangeHigh);
            out = std::move(o);
            break;
        }
        case DeclKind::Trigger: {
            const auto& t = static_cast<const TriggerDecl&>(d);
            auto o = std::make_unique<TriggerDecl>(r);
            o->params = params(t.params);
            o->commands = commands(t.commands);
            out = std::move(o);
            break;
        }
        case DeclKind::Object: return object(static_cast<const ObjectDecl&>(d), nullptr);
        case DeclKind::Spawn: {
            auto o = std::make_unique<SpawnDecl>(r);
            o->args = exprs(static_cast<const SpawnDecl&>(d).args);
            out = std::move(o);
            break;
        }
    }
    base(d, *out);
    return out;
}

}  // namespace

DeclPtr cloneParsed(const Decl& decl, int file, int64_t shift) { return Cloner(file, shift).decl(decl); }

}  // namespace psys::ast
