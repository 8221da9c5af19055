#include "frontend/parse.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <limits>
#include <optional>
#include <string_view>

#include <antlr4-runtime.h>
#include <fmt/format.h>

#include "PsysLexer.h"
#include "PsysParser.h"
#include "frontend/parse_cache.h"
#include "frontend/syntax_errors.h"

namespace psys {

std::vector<uint32_t> codePointOffsets(const std::string& text) {
    std::vector<uint32_t> offsets;
    offsets.reserve(text.size() + 1);
    for (uint32_t i = 0; i < text.size(); ++i)
        if ((static_cast<unsigned char>(text[i]) & 0xC0) != 0x80) offsets.push_back(i);
    offsets.push_back(static_cast<uint32_t>(text.size()));
    return offsets;
}

namespace {

using grammar::PsysParser;
using namespace ast;

// Drops ANTLR's default "line 1:2 mismatched input" printing; the reporter words errors instead.
class SilentListener : public antlr4::BaseErrorListener {};

class AstBuilder {
public:
    AstBuilder(int file, std::vector<uint32_t> offsets, DiagnosticEngine& diags)
        : file_(file), offsets_(std::move(offsets)), diags_(diags) {}

    std::unique_ptr<Module> build(PsysParser::FileContext* ctx) {
        auto module = std::make_unique<Module>();
        module->file = file_;
        for (auto* item : ctx->topItem()) module->decls.push_back(topItem(item));
        return module;
    }

private:
    SourceRange range(antlr4::Token* start, antlr4::Token* stop) const {
        auto at = [&](size_t i) { return i < offsets_.size() ? offsets_[i] : offsets_.back(); };
        if (!stop || stop->getStopIndex() + 1 < start->getStartIndex())  // empty rule
            return {file_, at(start->getStartIndex()), at(start->getStartIndex())};
        return {file_, at(start->getStartIndex()), at(stop->getStopIndex() + 1)};
    }
    SourceRange range(antlr4::ParserRuleContext* ctx) const { return range(ctx->getStart(), ctx->getStop()); }
    SourceRange range(antlr4::tree::TerminalNode* node) const {
        return range(node->getSymbol(), node->getSymbol());
    }

    DeclPtr topItem(PsysParser::TopItemContext* ctx) {
        if (auto* c = ctx->importDecl()) {
            auto d = std::make_unique<ImportDecl>(range(c));
            std::string quoted = c->STRING()->getText();
            d->path = unquote(quoted);
            d->pathRange = range(c->STRING());
            return d;
        }
        if (auto* c = ctx->fileAttribute()) {
            auto d = std::make_unique<FileAttributeDecl>(range(c));
            d->attribute = attribute(c->attribute());
            d->name = d->attribute.name;
            d->nameRange = d->attribute.nameRange;
            return d;
        }
        if (auto* c = ctx->constDecl()) {
            auto d = std::make_unique<ConstDecl>(range(c));
            name(*d, c->IDENT());
            if (c->typeRef()) d->annotation = typeRef(c->typeRef());
            d->value = expr(c->expr());
            return d;
        }
        if (auto* c = ctx->fnDecl()) return fnDecl(c);
        if (auto* c = ctx->externDecl()) {
            auto d = std::make_unique<ExternDecl>(range(c));
            name(*d, c->IDENT());
            d->type = typeRef(c->typeRef());
            auto exprs = c->expr();
            bool hasDefault = false;
            for (auto* child : c->children)
                if (child->getText() == "=") hasDefault = true;
            size_t next = 0;
            if (hasDefault) d->defaultValue = expr(exprs.at(next++));
            if (exprs.size() >= next + 2) {
                d->rangeLow = expr(exprs[next]);
                d->rangeHigh = expr(exprs[next + 1]);
            }
            return d;
        }
        if (auto* c = ctx->triggerDecl()) {
            auto d = std::make_unique<TriggerDecl>(range(c));
            name(*d, c->IDENT());
            if (c->paramList()) d->params = params(c->paramList());
            for (auto* cmd : c->command()) d->commands.push_back(command(cmd));
            return d;
        }
        if (auto* c = ctx->objectDecl()) return objectDecl(c, nullptr);
        auto* c = ctx->spawnDecl();
        auto d = std::make_unique<SpawnDecl>(range(c));
        name(*d, c->IDENT());
        if (c->argList()) d->args = args(c->argList());
        return d;
    }

    static std::string unquote(const std::string& quoted) {
        std::string out;
        for (size_t i = 1; i + 1 < quoted.size(); ++i) {
            if (quoted[i] == '\\' && i + 2 < quoted.size()) ++i;
            out += quoted[i];
        }
        return out;
    }

    void name(Decl& d, antlr4::tree::TerminalNode* ident) {
        d.name = ident->getText();
        d.nameRange = range(ident);
    }

    TypeAnnotation typeRef(PsysParser::TypeRefContext* ctx) {
        TypeAnnotation t{Type::error(), range(ctx), {}};
        if (auto* named = dynamic_cast<PsysParser::NamedTypeContext*>(ctx)) {
            std::string spelled = named->getText();
            t.spelling = spelled;
            if (auto known = Type::fromName(spelled)) t.type = *known;
            else
                diags_.error(t.range, fmt::format("unknown type `{}`", spelled))
                    .notes.push_back({t.range, "the types are bool, float, vec2, vec3 (point), vec4 (color) "
                                               "and tuples of them such as (vec3, vec3)"});
        } else {
            auto* tuple = static_cast<PsysParser::TupleTypeContext*>(ctx);
            std::vector<Type> elements;
            for (auto* e : tuple->typeRef()) elements.push_back(typeRef(e).type);
            t.type = Type::tuple(std::move(elements));
        }
        return t;
    }

    std::vector<Param> params(PsysParser::ParamListContext* ctx) {
        std::vector<Param> out;
        for (auto* p : ctx->param()) out.push_back({p->IDENT()->getText(), range(p->IDENT()), typeRef(p->typeRef())});
        return out;
    }

    Attribute attribute(PsysParser::AttributeContext* ctx) {
        Attribute a;
        a.name = ctx->IDENT()->getText();
        a.range = range(ctx);
        a.nameRange = range(ctx->IDENT());
        if (ctx->STRING()) {
            a.text = unquote(ctx->STRING()->getText());
            a.textRange = range(ctx->STRING());
        }
        for (auto* e : ctx->expr()) a.args.push_back(expr(e));
        return a;
    }

    DeclPtr fnDecl(PsysParser::FnDeclContext* ctx) {
        auto d = std::make_unique<FnDecl>(range(ctx));
        name(*d, ctx->IDENT());
        if (ctx->paramList()) d->params = params(ctx->paramList());
        if (ctx->typeRef()) d->returnType = typeRef(ctx->typeRef());
        if (auto* body = dynamic_cast<PsysParser::FnExprBodyContext*>(ctx->fnBody())) {
            d->body = expr(body->expr());
        } else {
            auto* block = static_cast<PsysParser::FnBlockBodyContext*>(ctx->fnBody());
            for (auto* l : block->letStmt()) {
                auto let = std::make_unique<LetStmt>();
                let->name = l->IDENT()->getText();
                let->nameRange = range(l->IDENT());
                if (l->typeRef()) let->annotation = typeRef(l->typeRef());
                let->value = expr(l->expr());
                d->lets.push_back(std::move(let));
            }
            d->body = expr(block->expr());
        }
        return d;
    }

    std::unique_ptr<ObjectDecl> objectDecl(PsysParser::ObjectDeclContext* ctx, const ObjectDecl* parent) {
        auto d = std::make_unique<ObjectDecl>(range(ctx));
        name(*d, ctx->IDENT());
        d->parent = parent;
        for (auto* a : ctx->attribute()) d->attributes.push_back(attribute(a));
        if (ctx->paramList()) d->params = params(ctx->paramList());
        for (auto* item : ctx->objectItem()) {
            if (auto* e = item->equation()) d->equations.push_back(equation(e));
            else if (auto* c = item->command()) d->commands.push_back(command(c));
            else d->children.push_back(objectDecl(item->objectDecl(), d.get()));
        }
        return d;
    }

    EquationPtr equation(PsysParser::EquationContext* ctx) {
        auto eq = std::make_unique<Equation>();
        eq->range = range(ctx);
        if (auto* single = dynamic_cast<PsysParser::SingleEquationContext*>(ctx)) {
            eq->names.push_back(single->IDENT()->getText());
            eq->nameRanges.push_back(range(single->IDENT()));
            if (single->typeRef()) eq->annotation = typeRef(single->typeRef());
            eq->value = expr(single->expr());
        } else {
            auto* tuple = static_cast<PsysParser::TupleEquationContext*>(ctx);
            for (auto* id : tuple->IDENT()) {
                eq->names.push_back(id->getText());
                eq->nameRanges.push_back(range(id));
            }
            eq->value = expr(tuple->expr());
        }
        return eq;
    }

    CommandPtr command(PsysParser::CommandContext* ctx) {
        auto c = std::make_unique<Command>();
        c->range = range(ctx);
        c->keywordRange = range(ctx->getStart(), ctx->getStart());
        if (auto* p = dynamic_cast<PsysParser::DrawCmdContext*>(ctx)) {
            c->kind = CommandKind::Draw;
            c->draw = core::drawKindFromName(p->drawing->getText()).value_or(core::DrawKind::Point);
            if (p->argList()) c->args = args(p->argList());
        } else if (auto* k = dynamic_cast<PsysParser::KillCmdContext*>(ctx)) {
            c->kind = CommandKind::Kill;
            if (k->expr()) c->cond = expr(k->expr());
        } else if (auto* e = dynamic_cast<PsysParser::EmitCmdContext*>(ctx)) {
            c->kind = CommandKind::Emit;
            c->target = e->IDENT()->getText();
            c->targetRange = range(e->IDENT());
            if (e->argList()) c->args = args(e->argList());
            if (e->emitRate()) c->rate = expr(e->emitRate()->expr());
            if (e->emitCount()) c->count = expr(e->emitCount()->expr());
        } else if (auto* n = dynamic_cast<PsysParser::NotifyCmdContext*>(ctx)) {
            c->kind = CommandKind::Notify;
            std::string quoted = n->STRING()->getText();
            c->event = quoted.size() >= 2 ? quoted.substr(1, quoted.size() - 2) : quoted;
            c->eventRange = range(n->STRING());
            if (n->argList()) c->args = args(n->argList());
        } else if (auto* on = dynamic_cast<PsysParser::OnCmdContext*>(ctx)) {
            c->kind = CommandKind::On;
            c->event = on->IDENT()->getText();
            c->eventRange = range(on->IDENT());
            for (auto* inner : on->command()) c->body.push_back(command(inner));
        } else {
            auto* w = static_cast<PsysParser::WhenCmdContext*>(ctx);
            c->kind = CommandKind::When;
            c->cond = expr(w->expr());
            for (auto* inner : w->command()) c->body.push_back(command(inner));
        }
        return c;
    }

    std::vector<ExprPtr> args(PsysParser::ArgListContext* ctx) {
        std::vector<ExprPtr> out;
        for (auto* e : ctx->expr()) out.push_back(expr(e));
        return out;
    }

    // ---------------------------------------------------------------- expressions

    ExprPtr expr(PsysParser::ExprContext* ctx) {
        ExprPtr init = conditional(ctx->conditional());
        if (!ctx->expr()) return init;
        ExprPtr next = expr(ctx->expr());
        return std::make_unique<FollowedByExpr>(range(ctx), std::move(init), std::move(next));
    }

    ExprPtr conditional(PsysParser::ConditionalContext* ctx) {
        if (auto* t = dynamic_cast<PsysParser::TernaryExprContext*>(ctx)) {
            ExprPtr cond = binary(t->logicalOr());
            if (!t->expr()) return cond;
            return std::make_unique<ConditionalExpr>(range(ctx), std::move(cond), expr(t->expr()),
                                                     conditional(t->conditional()));
        }
        auto* i = static_cast<PsysParser::IfExprContext*>(ctx);
        return std::make_unique<ConditionalExpr>(range(ctx), expr(i->expr(0)), expr(i->expr(1)),
                                                 conditional(i->conditional()));
    }

    static BinaryOp binaryOp(const std::string& text) {
        static const std::pair<const char*, BinaryOp> table[] = {
            {"+", BinaryOp::Add}, {"-", BinaryOp::Sub}, {"*", BinaryOp::Mul}, {"/", BinaryOp::Div},
            {"%", BinaryOp::Mod}, {"<", BinaryOp::Lt},  {"<=", BinaryOp::Le}, {">", BinaryOp::Gt},
            {">=", BinaryOp::Ge}, {"==", BinaryOp::Eq}, {"!=", BinaryOp::Ne}, {"&&", BinaryOp::And},
            {"||", BinaryOp::Or}};
        for (auto& [spelled, op] : table)
            if (text == spelled) return op;
        return BinaryOp::Add;
    }

    // All binary levels share one shape: operand (op operand)*, left-associative.
    ExprPtr binary(antlr4::ParserRuleContext* ctx) {
        if (auto* u = dynamic_cast<PsysParser::UnaryContext*>(ctx)) return unary(u);
        ExprPtr lhs;
        BinaryOp op = BinaryOp::Add;
        SourceRange opRange;
        for (auto* child : ctx->children) {
            if (auto* term = dynamic_cast<antlr4::tree::TerminalNode*>(child)) {
                op = binaryOp(term->getText());
                opRange = range(term);
                continue;
            }
            ExprPtr operand = binary(static_cast<antlr4::ParserRuleContext*>(child));
            if (!lhs) {
                lhs = std::move(operand);
            } else {
                SourceRange r = SourceRange::join(lhs->range, operand->range);
                lhs = std::make_unique<BinaryExpr>(r, op, opRange, std::move(lhs), std::move(operand));
            }
        }
        return lhs;
    }

    ExprPtr unary(PsysParser::UnaryContext* ctx) {
        if (auto* p = dynamic_cast<PsysParser::PrefixExprContext*>(ctx)) {
            std::string op = p->getStart()->getText();
            UnaryOp u = op == "-" ? UnaryOp::Neg : op == "!" ? UnaryOp::Not : UnaryOp::Plus;
            return std::make_unique<UnaryExpr>(range(ctx), u, unary(p->unary()));
        }
        return postfix(static_cast<PsysParser::PostfixOnlyContext*>(ctx)->postfix());
    }

    ExprPtr postfix(PsysParser::PostfixContext* ctx) {
        ExprPtr e = primary(ctx->primary());
        for (auto* id : ctx->IDENT()) {
            SourceRange r = SourceRange::join(e->range, range(id));
            e = std::make_unique<MemberExpr>(r, std::move(e), id->getText(), range(id));
        }
        return e;
    }

    ExprPtr primary(PsysParser::PrimaryContext* ctx) {
        SourceRange r = range(ctx);
        if (auto* n = dynamic_cast<PsysParser::NumberLitContext*>(ctx)) {
            std::string text = n->NUMBER()->getText();
            double value = std::strtod(text.c_str(), nullptr);
            // Numbers are floats: one that rounds past the largest float would silently be
            // infinite. 3.4028235e38 itself rounds to the largest; from halfway to the next
            // power of two on, a number rounds to infinity.
            if (value >= 3.4028235677973366e38)
                diags_.error(r, fmt::format("the number {} is too large for a float: it rounds to infinity (the largest "
                                            "float is 3.4028235e38)", text));
            return std::make_unique<NumberExpr>(r, value, text);
        }
        if (auto* b = dynamic_cast<PsysParser::BoolLitContext*>(ctx))
            return std::make_unique<BoolExpr>(r, b->getText() == "true");
        if (auto* c = dynamic_cast<PsysParser::CallExprContext*>(ctx)) {
            auto call = std::make_unique<CallExpr>(r, c->IDENT()->getText(), range(c->IDENT()));
            if (c->argList()) call->args = args(c->argList());
            return call;
        }
        if (auto* n = dynamic_cast<PsysParser::NameExprContext*>(ctx))
            return std::make_unique<NameExpr>(r, n->IDENT()->getText());
        auto* p = static_cast<PsysParser::ParenExprContext*>(ctx);
        if (p->expr().size() > 1) {
            auto tuple = std::make_unique<TupleExpr>(r);
            for (auto* e : p->expr()) tuple->elements.push_back(expr(e));
            return tuple;
        }
        ExprPtr inner = expr(p->expr(0));
        inner->range = r;  // keep the parentheses in the range for carets
        return inner;
    }

    int file_;
    std::vector<uint32_t> offsets_;
    DiagnosticEngine& diags_;
};

}  // namespace

namespace {

// Where a `/*` opens that no `*/` closes (outside line comments and strings), if one does.
// The lexer would read it as `/` and `*`, and the parser report a cascade somewhere else.
std::optional<uint32_t> unterminatedComment(std::string_view text) {
    for (size_t i = 0; i + 1 < text.size(); ++i) {
        if (text[i] == '"') {  // a string ends at its quote or the end of its line
            for (++i; i < text.size() && text[i] != '"' && text[i] != '\n' && text[i] != '\r'; ++i)
                if (text[i] == '\\') ++i;
        } else if (text[i] == '/' && text[i + 1] == '/') {
            i = text.find_first_of("\r\n", i);  // (the lexer's line comment ends at either)
            if (i == std::string_view::npos) return std::nullopt;
        } else if (text[i] == '/' && text[i + 1] == '*') {
            size_t close = text.find("*/", i + 2);
            if (close == std::string_view::npos) return static_cast<uint32_t>(i);
            i = close + 1;
        }
    }
    return std::nullopt;
}

// The first place brackets nest deeper than kMaxNesting, or more than kMaxNesting prefix
// operators stand in a row (`- - - x`), outside comments and strings. The parser recurses
// at each; clang's bracket limit is the model.
constexpr int kMaxNesting = 256;
std::optional<uint32_t> tooDeep(std::string_view text) {
    int depth = 0, prefixes = 0;
    bool operand = false;  // the last token ends an operand: a `-` after it is binary
    for (size_t i = 0; i < text.size(); ++i) {
        char c = text[i];
        if (c == '"') {
            for (++i; i < text.size() && text[i] != '"' && text[i] != '\n' && text[i] != '\r'; ++i)
                if (text[i] == '\\') ++i;
            operand = true;
            continue;
        }
        if (c == '/' && i + 1 < text.size() && (text[i + 1] == '/' || text[i + 1] == '*')) {
            size_t end = text[i + 1] == '/' ? text.find_first_of("\r\n", i) : text.find("*/", i + 2);
            if (end == std::string_view::npos) return std::nullopt;
            i = text[i + 1] == '/' ? end : end + 1;
            continue;
        }
        if (c == ' ' || c == '\t' || c == '\r' || c == '\n') continue;
        if (c == '(' || c == '{') {
            if (++depth > kMaxNesting) return static_cast<uint32_t>(i);
        } else if (c == ')' || c == '}') {
            depth = std::max(0, depth - 1);
        }
        bool prefix = !operand && (c == '-' || c == '+' || c == '!');
        prefixes = prefix ? prefixes + 1 : 0;
        if (prefixes > kMaxNesting) return static_cast<uint32_t>(i);
        operand = std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.' || c == ')' || c == '}';
    }
    return std::nullopt;
}

}  // namespace

namespace {

// Reports what keeps `text` from being parsed at all (its size, its encoding, an
// unterminated comment, nesting too deep for the parser's recursion), if anything does.
std::optional<SourceRange> unparsable(int file, const std::string& text, DiagnosticEngine& diags) {
    if (text.size() > kMaxSourceBytes) {
        diags.error({file, 0, 0}, fmt::format("this file is {} bytes, more than the {} a source file may be",
                                              text.size(), kMaxSourceBytes));
        return SourceRange{file, 0, 0};
    }
    // The lexer reads code points: a file must be UTF-8 (ASCII is), and one that is not is
    // reported at its first bad byte rather than read wrongly.
    if (auto bad = firstInvalidUtf8(text)) {
        diags.error({file, *bad, *bad + 1}, fmt::format("this file is not valid UTF-8: byte 0x{:02X} cannot be here; "
                                                        "save it as UTF-8", static_cast<unsigned char>(text[*bad])));
        return SourceRange{file, *bad, *bad + 1};
    }
    if (auto open = unterminatedComment(text)) {
        diags.error({file, *open, *open + 2}, "unterminated comment: this `/*` has no `*/`");
        return SourceRange{file, *open, *open + 2};
    }
    if (auto deep = tooDeep(text)) {
        diags.error({file, *deep, *deep + 1}, fmt::format("nesting exceeds the maximum of {} levels (brackets, or prefix "
                                                          "operators in a row); split the expression with a `let` or an "
                                                          "equation", kMaxNesting));
        return SourceRange{file, *deep, *deep + 1};
    }
    return std::nullopt;
}

}  // namespace

std::unique_ptr<Module> parseText(int file, std::string_view text, uint32_t shift, DiagnosticEngine& diags,
                                  bool report, std::vector<LexedToken>* lexed) {
    antlr4::ANTLRInputStream input(text.data(), text.size());
    grammar::PsysLexer lexer(&input);
    lexer.removeErrorListeners();
    antlr4::CommonTokenStream tokens(&lexer);
    PsysParser parser(&tokens);
    parser.removeErrorListeners();
    SilentListener silent;
    parser.addErrorListener(&silent);
    std::vector<uint32_t> offsets = codePointOffsets(std::string(text));
    // ANTLR's stream has dropped a leading byte order mark: its first character is the
    // one after it.
    if (text.starts_with(kByteOrderMark)) offsets.erase(offsets.begin());
    if (shift)
        for (uint32_t& o : offsets) o += shift;

    int errorsBefore = diags.errorCount();
    // Two-stage parsing: the fast SLL prediction parses every valid file of this grammar;
    // only if it fails does the full LL parse run, with worded errors and recovery.
    PsysParser::FileContext* tree = nullptr;
    parser.getInterpreter<antlr4::atn::ParserATNSimulator>()->setPredictionMode(antlr4::atn::PredictionMode::SLL);
    parser.setErrorHandler(std::make_shared<antlr4::BailErrorStrategy>());
    try {
        tree = parser.file();
    } catch (const antlr4::ParseCancellationException&) {
        tree = nullptr;
    }
    if (!tree) {
        if (!report) return nullptr;
        tokens.seek(0);
        parser.reset();
        parser.getInterpreter<antlr4::atn::ParserATNSimulator>()->setPredictionMode(antlr4::atn::PredictionMode::LL);
        parser.setErrorHandler(std::make_shared<SyntaxErrorReporter>(diags, file, offsets));
        tree = parser.file();
    }
    if (diags.errorCount() > errorsBefore || parser.getNumberOfSyntaxErrors() > 0) return nullptr;
    if (lexed)
        for (antlr4::Token* t : tokens.getTokens())
            if (t->getType() != antlr4::Token::EOF)
                lexed->push_back({static_cast<int>(t->getType()), offsets[t->getStartIndex()] - shift,
                                  offsets[t->getStopIndex() + 1] - shift});
    AstBuilder builder(file, std::move(offsets), diags);
    return builder.build(tree);
}

std::unique_ptr<Module> parseModule(int file, const SourceManager& sources, DiagnosticEngine& diags, ParseCache* cache,
                                    const std::vector<bool>* keep) {
    const std::string& text = sources.file(file).text();
    if (unparsable(file, text, diags)) return nullptr;
    auto module = cache ? cache->parse(file, text, diags, keep) : parseText(file, text, 0, diags, true);
    if (module) module->path = sources.file(file).path();
    return module;
}

}  // namespace psys
