// The index: one walk over every module's declarations and expressions. A name records
// what it refers to (hover text and the declaration's place); any other expression its
// type; declarations their own names, so hovering a declaration explains it too.
#include "lsp/index_builder.h"

#include <fmt/format.h>

#include "frontend/builtins.h"

namespace psys::lsp {

using namespace ast;

namespace {

std::string code(const std::string& text) { return "```psys\n" + text + "\n```"; }

std::string typeText(const Type& t) { return t.isVague() ? "?" : t.str(); }

std::string paramText(const Param& p) {
    return p.name + ": " + (p.type.spelling.empty() ? typeText(p.type.type) : p.type.spelling);
}

std::string paramList(const std::vector<Param>& params) {
    std::string s;
    for (size_t i = 0; i < params.size(); ++i) s += (i ? ", " : "") + paramText(params[i]);
    return s;
}

std::string builtinVariableDoc(const std::string& name) {
    if (name == "age") return "seconds since this object was created";
    if (name == "time") return "seconds since the system started";
    return "the length of the current step in seconds";
}

class Walker {
public:
    Walker(const Program& program, Analysis& out) : program_(program), out_(out) {}

    void module(const Module& m, bool main) {
        main_ = main;
        for (const DeclPtr& d : m.decls) {
            if (main) out_.marks.push_back(mark(d->range.begin));
            decl(*d, main);
        }
    }

    IndexMark mark(uint32_t begin) const {
        return {begin, out_.occurrences.size(), out_.symbols.size(), out_.globals.size(), out_.scopes.size(),
                out_.hints.size(), out_.integrating.size(), out_.members.size()};
    }

private:
    void add(SourceRange range, std::string hover, std::optional<SourceRange> definition = std::nullopt,
             Token token = {}) {
        if (range.valid())
            out_.occurrences.push_back({range, std::make_shared<const std::string>(std::move(hover)), definition, token});
    }

    struct Described {
        std::string hover;
        std::optional<SourceRange> definition;
        Token token;
    };

    // What a resolved name refers to: its hover text, its declaration, its kind.
    Described describe(const std::string& name, const Ref& ref, const Type& type) {
        using K = Ref::Kind;
        using T = TokenType;
        std::string t = name + ": " + typeText(type);
        switch (ref.kind) {
            case K::Param:
                return {code(t) + "\n\nparameter of `" + ref.object->name + "`", ref.object->params[ref.index].nameRange,
                        {T::Parameter}};
            case K::Equation:
                return {code(t) + "\n\nequation of `" + (ref.object ? ref.object->name : "?") + "`",
                        ref.equation->nameRanges[static_cast<size_t>(ref.index)], {T::Variable}};
            case K::Const: return {code("const " + t), ref.constant->nameRange, {T::Variable, kReadonly}};
            case K::Extern: return {code("extern " + t) + "\n\nset by the host", ref.externVar->nameRange, {T::Macro}};
            case K::FnParam:
                return {code(t) + "\n\nparameter of `" + ref.fn->name + "`", ref.fn->params[ref.index].nameRange,
                        {T::Parameter}};
            case K::Let: return {code("let " + t), ref.let->nameRange, {T::Variable}};
            case K::TriggerParam:
                return {code(t) + "\n\nparameter of trigger `" + ref.trigger->name + "`",
                        ref.trigger->params[ref.index].nameRange, {T::Parameter}};
            case K::Age: case K::Time: case K::Dt:
                return {code(t) + "\n\nbuilt-in: " + builtinVariableDoc(name), std::nullopt,
                        {T::Variable, kDefaultLibrary}};
            case K::Alive:
                return {code(t) + "\n\nfalse once the object has died", std::nullopt, {T::Variable, kDefaultLibrary}};
            case K::BuiltinConst: {
                const BuiltinConstant& c = builtinConstants()[static_cast<size_t>(findBuiltinConstant(name))];
                std::string v;
                for (int i = 0; i < std::max(1, c.type.width()); ++i) v += fmt::format("{}{:g}", i ? ", " : "", c.value[i]);
                return {code(t) + "\n\nbuilt-in constant (" + v + ")", std::nullopt,
                        {T::Variable, kReadonly | kDefaultLibrary}};
            }
            case K::Unresolved: break;
        }
        return {type.isVague() ? std::string() : code(t), std::nullopt, {}};
    }

    void expr(const Expr& e) {
        switch (e.kind) {
            case ExprKind::Number: case ExprKind::Bool: break;
            case ExprKind::Name: {
                auto& n = static_cast<const NameExpr&>(e);
                auto [hover, definition, token] = describe(n.name, n.ref, n.type);
                if (!hover.empty()) add(n.range, hover, definition, token);
                return;
            }
            case ExprKind::Call: {
                auto& c = static_cast<const CallExpr&>(e);
                if (c.builtin >= 0 && builtinFunction(c.builtin).name == "integrate") integrates_ = true;
                if (c.fn) add(c.calleeRange, code(signature(*c.fn)), c.fn->nameRange, {TokenType::Function});
                else if (c.builtin >= 0)
                    add(c.calleeRange, code(std::string(builtinFunction(c.builtin).signature)) + "\n\nbuilt-in function",
                        std::nullopt, {TokenType::Function, kDefaultLibrary});
                for (const ExprPtr& a : c.args) expr(*a);
                break;
            }
            case ExprKind::Member: {
                auto& m = static_cast<const MemberExpr&>(e);
                if (m.parent) {
                    add(m.base->range, code(signature(*m.parent)) + "\n\nan enclosing object, read live", m.parent->nameRange,
                        {TokenType::Class});
                    auto [hover, definition, token] = describe(m.member, m.parentRef, m.type);
                    add(m.memberRange, hover + "\n\nread live from `" + m.parent->name + "`", definition,
                        {TokenType::Property});
                    return;
                }
                expr(*m.base);
                if (!m.type.isVague()) add(m.memberRange, code("." + m.member + ": " + m.type.str()) + "\n\nswizzle");
                break;
            }
            case ExprKind::Unary: expr(*static_cast<const UnaryExpr&>(e).operand); break;
            case ExprKind::Binary: {
                auto& b = static_cast<const BinaryExpr&>(e);
                expr(*b.lhs);
                expr(*b.rhs);
                break;
            }
            case ExprKind::Conditional: {
                auto& c = static_cast<const ConditionalExpr&>(e);
                for (const Expr* x : {c.cond.get(), c.thenExpr.get(), c.elseExpr.get()}) expr(*x);
                break;
            }
            case ExprKind::Tuple:
                for (const ExprPtr& x : static_cast<const TupleExpr&>(e).elements) expr(*x);
                break;
            case ExprKind::FollowedBy: {
                auto& f = static_cast<const FollowedByExpr&>(e);
                expr(*f.init);
                expr(*f.next);
                break;
            }
        }
        if (!e.type.isVague()) add(e.range, code(e.type.str()));
    }

    void exprs(const std::vector<ExprPtr>& list) {
        for (const ExprPtr& e : list)
            if (e) expr(*e);
    }

    // A type as written (`ivel: vec3`): what the type is.
    void annotation(const TypeAnnotation& t) {
        std::string name = t.spelling.empty() ? t.type.str() : t.spelling;
        if (std::string_view doc = typeDoc(name); !doc.empty() && t.range.valid())
            add(t.range, code(name) + "\n\n" + std::string(doc), std::nullopt, {TokenType::None});
    }
    void annotation(const std::optional<TypeAnnotation>& t) {
        if (t) annotation(*t);
    }

    // A command's keyword: what the command does (a drawing: its parameters too).
    void keyword(const Command& c) {
        static constexpr std::string_view kWords[] = {"", "kill", "emit", "when", "on", "notify"};
        std::string_view word = c.kind == CommandKind::Draw ? core::drawKindName(c.draw) : kWords[static_cast<int>(c.kind)];
        std::string_view doc = commandDoc(word);
        if (doc.empty() || !c.keywordRange.valid()) return;
        std::string head = c.kind == CommandKind::Draw ? drawCallSignature(c.draw) : std::string(word);
        add(c.keywordRange, code(head) + "\n\n" + std::string(doc), std::nullopt, {TokenType::None});
    }

    void commands(const std::vector<CommandPtr>& list) {
        for (const CommandPtr& c : list) {
            keyword(*c);
            exprs(c->args);
            if (c->cond) expr(*c->cond);
            if (c->rate) expr(*c->rate);
            if (c->count) expr(*c->count);
            if (c->targetDecl)
                add(c->targetRange, code(signature(*c->targetDecl)), c->targetDecl->nameRange, {TokenType::Class});
            commands(c->body);
        }
    }

    void attribute(const Attribute& a) {
        add(a.nameRange, code("@" + a.name) + "\n\n" + std::string(attributeDoc(a.name)), std::nullopt,
            {TokenType::Decorator});
        exprs(a.args);
        // A method's, a shape's or a blend's name is no expression: its hover says what it is.
        if (a.args.size() != 1 || a.args[0]->kind != ExprKind::Name) return;
        const std::string& word = static_cast<const NameExpr&>(*a.args[0]).name;
        std::string doc = a.name == "integrator" ? integratorDoc(word)
                          : a.name == "shape"    ? std::string(shapeDoc(word))
                          : a.name == "blend"    ? std::string(blendDoc(word))
                                                 : std::string();
        if (!doc.empty())
            add(a.args[0]->range, code("@" + a.name + "(" + word + ")") + "\n\n" + doc, std::nullopt,
                {TokenType::EnumMember, kDefaultLibrary});
    }

    std::vector<Name> paramNames(const std::vector<Param>& params, const std::string& owner) {
        std::vector<Name> names;
        for (const Param& p : params) {
            annotation(p.type);
            names.push_back({p.name, paramText(p), "parameter of " + owner, CompletionKind::Variable});
            add(p.nameRange, code(paramText(p)) + "\n\nparameter of " + owner, p.nameRange,
                {TokenType::Parameter, kDeclaration});
        }
        return names;
    }

    Symbol object(const ObjectDecl& o, std::vector<const ObjectDecl*>& enclosing) {
        Symbol s{o.name, o.params.empty() ? "" : "(" + paramList(o.params) + ")", SymbolKind::Class, o.range, o.nameRange, {}};
        add(o.nameRange, code(signature(o)), o.nameRange, {TokenType::Class, kDeclaration});
        for (const Attribute& a : o.attributes) attribute(a);
        Scope scope{o.range, paramNames(o.params, "`" + o.name + "`")};
        std::vector<Name> members = {{"alive", "bool", "false once the object has died", CompletionKind::Property},
                                     {"age", "float", builtinVariableDoc("age"), CompletionKind::Property}};
        for (const Param& p : o.params) {
            s.children.push_back({p.name, paramText(p), SymbolKind::Property, p.nameRange, p.nameRange, {}});
            members.push_back({p.name, paramText(p), "parameter of `" + o.name + "`", CompletionKind::Property});
        }
        integrates_ = false;
        for (const EquationPtr& eq : o.equations) {
            annotation(eq->annotation);
            for (size_t i = 0; i < eq->names.size(); ++i) {
                std::string t = eq->names[i] + ": " + (i < eq->types.size() ? typeText(eq->types[i]) : "?");
                if (main_ && i < eq->types.size() && !eq->types[i].isVague())
                    out_.hints.push_back({eq->nameRanges[i], ": " + eq->types[i].str(), 1});
                add(eq->nameRanges[i], code(t) + "\n\nequation of `" + o.name + "`", eq->nameRanges[i],
                    {TokenType::Variable, kDeclaration});
                s.children.push_back({eq->names[i], t, SymbolKind::Field, eq->range, eq->nameRanges[i], {}});
                scope.names.push_back({eq->names[i], t, "equation of `" + o.name + "`", CompletionKind::Field});
                members.push_back({eq->names[i], t, "equation of `" + o.name + "`", CompletionKind::Property});
            }
            expr(*eq->value);
        }
        if (main_ && integrates_) out_.integrating.push_back(o.nameRange);
        commands(o.commands);
        for (const ObjectDecl* e : enclosing)
            scope.names.push_back({e->name, signature(*e), "an enclosing object: read it live as `" + e->name + ".name`",
                                   CompletionKind::Class});
        enclosing.push_back(&o);
        for (const auto& child : o.children) {
            scope.names.push_back({child->name, signature(*child), "a nested object", CompletionKind::Class});
            s.children.push_back(object(*child, enclosing));
        }
        enclosing.pop_back();
        out_.scopes.push_back(std::move(scope));
        out_.members.emplace_back(o.name, std::move(members));
        return s;
    }

    void decl(const Decl& d, bool main) {
        std::optional<Symbol> symbol;
        auto global = [&](const std::string& detail, const std::string& doc, CompletionKind kind) {
            out_.globals.push_back({d.name, detail, doc, kind});
        };
        switch (d.kind) {
            case DeclKind::Import: {
                auto& i = static_cast<const ImportDecl&>(d);
                if (i.module >= 0) {
                    int file = program_.modules[static_cast<size_t>(i.module)]->file;
                    add(i.pathRange, code("import \"" + i.path + "\""), SourceRange{file, 0, 0});
                }
                return;
            }
            case DeclKind::Attribute: attribute(static_cast<const FileAttributeDecl&>(d).attribute); return;
            case DeclKind::Const: {
                auto& c = static_cast<const ConstDecl&>(d);
                annotation(c.annotation);
                std::string t = "const " + c.name + ": " + typeText(c.type);
                add(c.nameRange, code(t), c.nameRange, {TokenType::Variable, kDeclaration | kReadonly});
                expr(*c.value);
                global(t, "constant", CompletionKind::Constant);
                symbol = Symbol{c.name, typeText(c.type), SymbolKind::Constant, c.range, c.nameRange, {}};
                break;
            }
            case DeclKind::Fn: {
                auto& f = static_cast<const FnDecl&>(d);
                add(f.nameRange, code(signature(f)), f.nameRange, {TokenType::Function, kDeclaration});
                Scope scope{f.range, paramNames(f.params, "`" + f.name + "`"), true};
                annotation(f.returnType);
                for (const auto& let : f.lets) {
                    annotation(let->annotation);
                    std::string t = "let " + let->name + ": " + typeText(let->type);
                    if (main && !let->type.isVague()) out_.hints.push_back({let->nameRange, ": " + let->type.str(), 1});
                    add(let->nameRange, code(t), let->nameRange, {TokenType::Variable, kDeclaration});
                    scope.names.push_back({let->name, t, "", CompletionKind::Variable});
                    expr(*let->value);
                }
                expr(*f.body);
                out_.scopes.push_back(std::move(scope));
                global(signature(f), "function", CompletionKind::Function);
                symbol = Symbol{f.name, signature(f).substr(3 + f.name.size()), SymbolKind::Function, f.range, f.nameRange, {}};
                break;
            }
            case DeclKind::Extern: {
                auto& x = static_cast<const ExternDecl&>(d);
                annotation(x.type);
                std::string t = "extern " + x.name + ": " + (x.type.spelling.empty() ? typeText(x.type.type) : x.type.spelling);
                add(x.nameRange, code(t) + "\n\nset by the host", x.nameRange, {TokenType::Macro, kDeclaration});
                for (const Expr* e : {x.defaultValue.get(), x.rangeLow.get(), x.rangeHigh.get()})
                    if (e) expr(*e);
                global(t, "set by the host", CompletionKind::Variable);
                symbol = Symbol{x.name, typeText(x.type.type), SymbolKind::Variable, x.range, x.nameRange, {}};
                break;
            }
            case DeclKind::Trigger: {
                auto& t = static_cast<const TriggerDecl&>(d);
                add(t.nameRange, code(signature(t)) + "\n\nfired by the host", t.nameRange, {TokenType::Event, kDeclaration});
                out_.scopes.push_back({t.range, paramNames(t.params, "trigger `" + t.name + "`")});
                commands(t.commands);
                global(signature(t), "fired by the host", CompletionKind::Event);
                symbol = Symbol{t.name, "(" + paramList(t.params) + ")", SymbolKind::Event, t.range, t.nameRange, {}};
                break;
            }
            case DeclKind::Object: {
                auto& o = static_cast<const ObjectDecl&>(d);
                std::vector<const ObjectDecl*> enclosing;
                symbol = object(o, enclosing);
                global(signature(o), "object", CompletionKind::Class);
                break;
            }
            case DeclKind::Spawn: {
                auto& s = static_cast<const SpawnDecl&>(d);
                if (s.targetDecl)
                    add(s.nameRange, code(signature(*s.targetDecl)), s.targetDecl->nameRange, {TokenType::Class});
                exprs(s.args);
                return;
            }
        }
        if (main && symbol) out_.symbols.push_back(std::move(*symbol));
    }

    const Program& program_;
    Analysis& out_;
    bool main_ = false;        // walking the main file
    bool integrates_ = false;  // the object being walked calls integrate
};

}  // namespace

std::string signature(const ObjectDecl& o) {
    return "object " + o.name + (o.params.empty() ? "" : "(" + paramList(o.params) + ")");
}

std::string signature(const FnDecl& f) {
    std::string result = f.returnType ? f.returnType->spelling : typeText(f.resultType);
    if (result.empty()) result = typeText(f.resultType);
    return "fn " + f.name + "(" + paramList(f.params) + ") -> " + result;
}

std::string signature(const TriggerDecl& t) {
    return "trigger " + t.name + (t.params.empty() ? "" : "(" + paramList(t.params) + ")");
}

void buildIndex(const Program& program, const SourceManager&, Analysis& out) {
    Walker walker(program, out);
    for (const auto& m : program.modules) walker.module(*m, m.get() == program.modules.back().get());
    out.marks.push_back(walker.mark(UINT32_MAX));
}

}  // namespace psys::lsp
