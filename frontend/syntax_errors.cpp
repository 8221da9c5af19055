#include "frontend/syntax_errors.h"

#include <set>

#include <fmt/format.h>

#include "PsysParser.h"

namespace psys {
namespace {

// `'#'`, or for what a terminal would not show, its code point: `U+0000`, `'→' (U+2192)`.
std::string describeCharacter(const std::string& utf8) {
    auto lead = static_cast<unsigned char>(utf8.empty() ? 0 : utf8[0]);
    uint32_t cp = lead;
    if (lead >= 0xC0 && utf8.size() > 1) {
        int extra = lead >= 0xF0 ? 3 : lead >= 0xE0 ? 2 : 1;
        cp = lead & (0x3F >> extra);
        for (int k = 1; k <= extra && static_cast<size_t>(k) < utf8.size(); ++k)
            cp = (cp << 6) | (static_cast<unsigned char>(utf8[static_cast<size_t>(k)]) & 0x3F);
    }
    if (cp < 0x20 || cp == 0x7F) return fmt::format("U+{:04X}", cp);
    if (cp < 0x80) return "'" + utf8 + "'";
    return fmt::format("'{}' (U+{:04X})", utf8, cp);
}

using grammar::PsysParser;

std::string literal(antlr4::Parser* parser, size_t type) {
    return parser->getVocabulary().getLiteralName(type);  // with quotes, e.g. "';'"
}

bool isKeyword(const std::string& literalName) {
    return literalName.size() > 2 && std::isalpha(static_cast<unsigned char>(literalName[1]));
}

// What the parser was inside of, in the user's words.
std::string ruleWords(antlr4::ParserRuleContext* ctx) {
    for (; ctx; ctx = dynamic_cast<antlr4::ParserRuleContext*>(ctx->parent)) {
        switch (ctx->getRuleIndex()) {
            case PsysParser::RuleImportDecl: return "import";
            case PsysParser::RuleAttribute: return "attribute";
            case PsysParser::RuleConstDecl: return "constant declaration";
            case PsysParser::RuleFnDecl: case PsysParser::RuleFnBody: return "function";
            case PsysParser::RuleLetStmt: return "let binding";
            case PsysParser::RuleExternDecl: return "extern declaration";
            case PsysParser::RuleSpawnDecl: return "spawn";
            case PsysParser::RuleParamList: case PsysParser::RuleParam: return "parameter list";
            case PsysParser::RuleEquation: return "equation";
            case PsysParser::RuleEmitRate: case PsysParser::RuleEmitCount: return "emit command";
            case PsysParser::RuleCommand: {
                auto* c = ctx;
                if (auto* d = dynamic_cast<PsysParser::DrawCmdContext*>(c)) return d->drawing->getText() + " command";
                if (dynamic_cast<PsysParser::KillCmdContext*>(c)) return "kill command";
                if (dynamic_cast<PsysParser::EmitCmdContext*>(c)) return "emit command";
                if (dynamic_cast<PsysParser::NotifyCmdContext*>(c)) return "notify command";
                if (dynamic_cast<PsysParser::WhenCmdContext*>(c)) return "when command";
                if (dynamic_cast<PsysParser::OnCmdContext*>(c)) return "`on` block";
                return "command";
            }
            case PsysParser::RuleTriggerDecl: return "trigger";
            case PsysParser::RuleObjectDecl: return "object";
            default: break;
        }
    }
    return "";
}

// Describes an expected-token set in words: "an expression", "a name", "';' or ','".
std::string describeExpected(antlr4::Parser* parser, const antlr4::misc::IntervalSet& expected) {
    std::set<size_t> types;
    for (ssize_t t : expected.toList()) types.insert(static_cast<size_t>(t));
    auto has = [&](std::initializer_list<const char*> lits) {
        for (const char* lit : lits) {
            bool found = false;
            for (size_t t : types) found |= literal(parser, t) == std::string("'") + lit + "'";
            if (!found) return false;
        }
        return true;
    };
    auto drop = [&](std::initializer_list<const char*> lits) {
        for (const char* lit : lits)
            for (auto it = types.begin(); it != types.end();)
                it = literal(parser, *it) == std::string("'") + lit + "'" ? types.erase(it) : std::next(it);
    };

    std::vector<std::string> words;
    bool exprStart = types.count(PsysParser::NUMBER) && types.count(PsysParser::IDENT) && has({"("});
    bool objectBody = has({"point", "kill", "emit", "notify", "when", "on", "object"});
    bool topLevel = has({"import", "const", "fn", "extern", "trigger", "object", "spawn"});
    if (topLevel) {
        words.push_back("a declaration (object, const, fn, extern, trigger, spawn or import)");
        drop({"import", "const", "fn", "extern", "trigger", "object", "spawn", "@"});
        types.erase(static_cast<size_t>(antlr4::Token::EOF));
    } else if (objectBody) {
        words.push_back("an equation, a command, a nested object");
        drop({"point", "sprite", "streak", "trail", "kill", "emit", "notify", "when", "on", "object", "@", "("});
        types.erase(PsysParser::IDENT);
    } else if (exprStart) {
        words.push_back("an expression");
        drop({"(", "-", "+", "!", "true", "false", "if"});
        types.erase(PsysParser::NUMBER);
        types.erase(PsysParser::IDENT);
    }
    // Operators that could continue an expression are noise when something else would end it.
    std::set<size_t> operators;
    for (size_t t : types) {
        std::string lit = literal(parser, t);
        static const std::set<std::string> ops = {"'+'", "'-'", "'*'", "'/'", "'%'", "'<'", "'<='", "'>'",
                                                  "'>='", "'=='", "'!='", "'&&'", "'||'", "'?'", "'->'", "'.'"};
        if (ops.count(lit)) operators.insert(t);
    }
    if (operators.size() < types.size() || !words.empty())
        for (size_t t : operators) types.erase(t);

    for (size_t t : types) {
        if (t == PsysParser::IDENT) words.push_back("a name");
        else if (t == PsysParser::NUMBER) words.push_back("a number");
        else if (t == PsysParser::STRING) words.push_back("a file name in quotes");
        else if (t == static_cast<size_t>(antlr4::Token::EOF)) words.push_back("end of file");
        else words.push_back(literal(parser, t));
    }
    // Every ')' of the grammar closes a comma-separated list (arguments, parameters, tuples),
    // but once the list's loop has exited ANTLR expects only the ')'.
    if (words.size() == 1 && words[0] == "')'") words.insert(words.begin(), "','");
    if (words.empty()) return "something else";
    std::string out;
    for (size_t i = 0; i < words.size(); ++i) {
        if (i > 0) out += i + 1 == words.size() ? " or " : ", ";
        out += words[i];
    }
    return out;
}

std::string describeFound(antlr4::Token* token) {
    if (token->getType() == antlr4::Token::EOF) return "end of file";
    return fmt::format("'{}'", token->getText());
}

}  // namespace

SourceRange SyntaxErrorReporter::tokenRange(antlr4::Token* token) const {
    auto at = [&](size_t index) {
        return index < byteOffset_.size() ? byteOffset_[index] : byteOffset_.back();
    };
    if (token->getType() == antlr4::Token::EOF) return {file_, at(byteOffset_.size() - 1), at(byteOffset_.size() - 1)};
    return {file_, at(token->getStartIndex()), at(token->getStopIndex() + 1)};
}

// Where a missing token belongs: just after the last token that was matched.
SourceRange SyntaxErrorReporter::afterPrevious(antlr4::Parser* parser) const {
    antlr4::TokenStream* stream = parser->getTokenStream();
    antlr4::Token* current = parser->getCurrentToken();
    for (ssize_t i = static_cast<ssize_t>(current->getTokenIndex()) - 1; i >= 0; --i) {
        antlr4::Token* t = stream->get(static_cast<size_t>(i));
        if (t->getChannel() == antlr4::Token::DEFAULT_CHANNEL) {
            SourceRange r = tokenRange(t);
            return {file_, r.end, r.end};
        }
    }
    return tokenRange(current);
}

// Whether `found` comes right after an attribute (`@name` or `@name(…)`): then a
// declaration that is not an object is an attribute in the wrong place, not a missing
// declaration.
bool followsAttribute(antlr4::Parser* parser, antlr4::Token* found) {
    antlr4::TokenStream* stream = parser->getTokenStream();
    std::vector<antlr4::Token*> before;  // default-channel tokens before `found`, nearest first
    for (ssize_t i = static_cast<ssize_t>(found->getTokenIndex()) - 1; i >= 0 && before.size() < 4096; --i)
        if (antlr4::Token* t = stream->get(static_cast<size_t>(i)); t->getChannel() == antlr4::Token::DEFAULT_CHANNEL)
            before.push_back(t);
    size_t at = 0;
    if (at < before.size() && before[at]->getText() == ")") {  // back over the arguments
        int depth = 0;
        for (; at < before.size(); ++at) {
            std::string text = before[at]->getText();
            depth += text == ")" ? 1 : text == "(" ? -1 : 0;
            if (depth == 0) break;
        }
        ++at;
    }
    return at + 1 < before.size() && before[at]->getType() == PsysParser::IDENT && before[at + 1]->getText() == "@";
}

void SyntaxErrorReporter::report(antlr4::Parser* parser, antlr4::Token* found,
                                 const antlr4::misc::IntervalSet& expected) {
    SourceRange where = tokenRange(found);
    if (found->getType() == PsysParser::UNKNOWN_CHAR) {
        std::string text = found->getText();
        if (text == "\"") diags_.error(where, "unterminated string: a file name needs a closing '\"' on the same line");
        else diags_.error(where, fmt::format("unexpected character {}", describeCharacter(text)));
        return;
    }
    if (keywordTakenForName(parser, found)) return;
    std::string context = ruleWords(parser->getContext());
    std::string in = context.empty() ? "" : " in " + context;
    std::string foundLit = literal(parser, found->getType());
    static const std::set<std::string> notObjects = {"'const'", "'fn'", "'extern'", "'trigger'", "'spawn'", "'import'"};
    if (notObjects.count(foundLit) && followsAttribute(parser, found)) {
        diags_.error(where, fmt::format("an attribute applies to an object: expected 'object' after it (or ';', to apply "
                                        "it to every object of the file), found {}",
                                        describeFound(found)));
        return;
    }
    if (expected.contains(static_cast<size_t>(PsysParser::IDENT)) && isKeyword(foundLit)) {
        diags_.error(where, fmt::format("expected a name{}, found the keyword {}, which is reserved", in,
                                        describeFound(found)));
        return;
    }
    diags_.error(where, fmt::format("expected {}{}, found {}", describeExpected(parser, expected), in,
                                    describeFound(found)));
}

antlr4::Token* SyntaxErrorReporter::singleTokenDeletion(antlr4::Parser* parser) {
    std::string text = parser->getCurrentToken()->getText();
    if (text == ";" || text == "}") return nullptr;
    return DefaultErrorStrategy::singleTokenDeletion(parser);
}

void SyntaxErrorReporter::reportNoViableAlternative(antlr4::Parser* parser, const antlr4::NoViableAltException& e) {
    report(parser, e.getOffendingToken(), parser->getExpectedTokens());
}

void SyntaxErrorReporter::reportInputMismatch(antlr4::Parser* parser, const antlr4::InputMismatchException& e) {
    report(parser, e.getOffendingToken(), e.getExpectedTokens());
}

void SyntaxErrorReporter::reportFailedPredicate(antlr4::Parser* parser, const antlr4::FailedPredicateException& e) {
    report(parser, e.getOffendingToken(), parser->getExpectedTokens());
}

// `on = 1;`: a keyword that starts a command (`on death { … }`) taken for a name; said at
// the keyword.
bool SyntaxErrorReporter::keywordTakenForName(antlr4::Parser* parser, antlr4::Token* found) {
    antlr4::Token* before = parser->getTokenStream()->LT(-1);
    if (!before || (found->getText() != "=" && found->getText() != ":") || !isKeyword(literal(parser, before->getType())))
        return false;
    diags_.error(tokenRange(before), fmt::format("expected a name, found the keyword {}, which is reserved",
                                                 describeFound(before)));
    return true;
}

void SyntaxErrorReporter::reportUnwantedToken(antlr4::Parser* parser) {
    if (inErrorRecoveryMode(parser)) return;
    beginErrorCondition(parser);
    antlr4::Token* token = parser->getCurrentToken();
    if (keywordTakenForName(parser, token)) return;
    if (token->getType() == PsysParser::UNKNOWN_CHAR) {
        report(parser, token, getExpectedTokens(parser));
        return;
    }
    std::string context = ruleWords(parser->getContext());
    diags_.error(tokenRange(token),
                 fmt::format("unexpected {}{}; expected {}", describeFound(token),
                             context.empty() ? "" : " in " + context,
                             describeExpected(parser, getExpectedTokens(parser))));
}

void SyntaxErrorReporter::reportMissingToken(antlr4::Parser* parser) {
    if (inErrorRecoveryMode(parser)) return;
    beginErrorCondition(parser);
    std::string expected = describeExpected(parser, getExpectedTokens(parser));
    std::string context = ruleWords(parser->getContext());
    diags_.error(afterPrevious(parser),
                 fmt::format("expected {}{}", expected,
                             context.empty() ? "" : (expected == "';'" ? " at end of " : " in ") + context));
}

}  // namespace psys
