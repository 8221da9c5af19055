// The canonical layout works on the token stream, not the AST, so that every comment stays
// where the author put it and nothing the parser drops can be lost: the output has the
// same tokens as the input, only the white space between them changes.
//
// Structure fixes the line breaks (one statement a line, blocks opened at the end of a
// line and closed on one of their own, each object attribute on a line); inside a
// statement the author's line breaks stay, and the continuation lines are indented one
// level past the line that opened the innermost bracket still open. A line longer than
// the width (100) is broken after a comma or an operator, by the same rule. Blank lines are
// kept (at most one) between statements. Trailing comments on consecutive lines line up; a
// block comment over several lines moves with its code, its own layout kept.
#include "frontend/format.h"

#include <algorithm>
#include <string_view>
#include <vector>

#include <antlr4-runtime.h>

#include "PsysLexer.h"
#include "frontend/parse.h"
#include "frontend/parse_cache.h"

namespace psys {
namespace {

using grammar::PsysLexer;

enum class Kind { Token, LineComment, BlockComment };

struct Atom {
    Kind kind = Kind::Token;
    int type = 0;  // the lexer's token type
    std::string_view text;  // (of the text laid out, which outlives its atoms)
    int newlinesBefore = 0;  // in the source, between the previous atom and this one
    bool endsAttribute = false;
    int column = 0;  // a block comment's: where it began on its line in the source
};

bool isToken(const Atom* atom, std::string_view text) {
    return atom && atom->kind == Kind::Token && atom->type != PsysLexer::STRING && atom->text == text;
}

size_t displayWidth(std::string_view text) {
    return static_cast<size_t>(
        std::count_if(text.begin(), text.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; }));
}

// Newlines, `//` and `/* */` comments in the text between two tokens (the lexer skips them);
// the gap starts at `from` in `whole`.
void addGap(std::string_view whole, size_t from, std::string_view gap, std::vector<Atom>& atoms, int& newlines) {
    for (size_t i = 0; i < gap.size();) {
        if (gap.compare(i, 2, "//") == 0) {
            size_t end = gap.find('\n', i);
            if (end == std::string_view::npos) end = gap.size();
            std::string_view text = gap.substr(i, end - i);
            while (!text.empty() && (text.back() == ' ' || text.back() == '\t' || text.back() == '\r'))
                text.remove_suffix(1);
            atoms.push_back({Kind::LineComment, 0, text, newlines, false});
            newlines = 0;
            i = end;
        } else if (gap.compare(i, 2, "/*") == 0) {
            size_t end = gap.find("*/", i + 2);
            end = end == std::string_view::npos ? gap.size() : end + 2;
            size_t lineStart = whole.rfind('\n', from + i == 0 ? 0 : from + i - 1);
            lineStart = lineStart == std::string_view::npos ? 0 : lineStart + 1;
            int column = static_cast<int>(displayWidth(whole.substr(lineStart, from + i - lineStart)));
            atoms.push_back({Kind::BlockComment, 0, gap.substr(i, end - i), newlines, false, column});
            newlines = 0;
            i = end;
        } else {
            if (gap[i] == '\n') ++newlines;
            ++i;
        }
    }
}

// The tokens of `text`. Null when the lexer meets a character the language does not have.
std::optional<std::vector<LexedToken>> lex(const std::string& text) {
    antlr4::ANTLRInputStream input(text);
    PsysLexer lexer(&input);
    lexer.removeErrorListeners();
    std::vector<uint32_t> offsets = codePointOffsets(text);
    std::vector<LexedToken> out;
    for (const auto& token : lexer.getAllTokens()) {
        if (token->getType() == PsysLexer::UNKNOWN_CHAR) return std::nullopt;
        out.push_back({static_cast<int>(token->getType()), offsets[token->getStartIndex()],
                       offsets[token->getStopIndex() + 1]});
    }
    return out;
}

// The tokens and comments of `text` in order, from its tokens.
std::vector<Atom> atomsOf(const std::string& text, const std::vector<LexedToken>& tokens) {
    std::vector<Atom> atoms;
    atoms.reserve(tokens.size() + tokens.size() / 8);  // (and the comments)
    uint32_t at = 0;
    int newlines = 0;
    for (const LexedToken& token : tokens) {
        addGap(text, at, std::string_view(text).substr(at, token.begin - at), atoms, newlines);
        atoms.push_back({Kind::Token, token.type, std::string_view(text).substr(token.begin, token.end - token.begin), newlines, false});
        newlines = 0;
        at = token.end;
    }
    addGap(text, at, std::string_view(text).substr(at), atoms, newlines);
    // An attribute ends at its name or at the `)` that closes its arguments.
    for (size_t i = 0; i + 1 < atoms.size(); ++i) {
        if (!isToken(&atoms[i], "@")) continue;
        size_t end = i + 1, depth = 0;
        for (size_t j = i + 2; j < atoms.size(); ++j) {
            if (atoms[j].kind != Kind::Token) continue;
            if (depth == 0 && !isToken(&atoms[j], "(")) break;
            if (isToken(&atoms[j], "(")) ++depth;
            if (isToken(&atoms[j], ")") && --depth == 0) {
                end = j;
                break;
            }
        }
        atoms[end].endsAttribute = true;
    }
    return atoms;
}

// A block comment over several lines moves with its code: its lines after the first are
// shifted as far as its start moved (from its column in the source to `column`), so a
// comment's own layout (a column of `*`, an indented example) stays as it was drawn.
std::string reindented(const Atom& comment, int column) {
    int shift = column - comment.column;
    if (shift == 0 || comment.text.find('\n') == std::string::npos) return std::string(comment.text);
    std::string out;
    size_t start = 0;
    for (bool first = true; start <= comment.text.size(); first = false) {
        size_t end = comment.text.find('\n', start);
        std::string_view line(comment.text.data() + start, (end == std::string::npos ? comment.text.size() : end) - start);
        bool blankLine = line.find_first_not_of(" \t\r") == std::string_view::npos;  // (no trailing spaces added)
        if (!first && shift > 0 && !blankLine) out += std::string(static_cast<size_t>(shift), ' ');
        if (!first && shift < 0) {
            size_t drop = 0;
            while (drop < line.size() && drop < static_cast<size_t>(-shift) && line[drop] == ' ') ++drop;
            line.remove_prefix(drop);
        }
        out += line;
        if (end == std::string::npos) break;
        out += '\n';
        start = end + 1;
    }
    return out;
}

// A block comment's text as the check of the layout compares it: its lines after the
// first without their indentation (which the layout moves).
std::string comparable(const Atom& atom) {
    if (atom.kind != Kind::BlockComment) return std::string(atom.text);
    std::string out;
    bool lineStart = false;
    for (char c : atom.text) {
        if (lineStart && (c == ' ' || c == '\t')) continue;
        lineStart = c == '\n';
        out += c;
    }
    return out;
}

bool endsOperand(const Atom& token) {
    return token.type == PsysLexer::NUMBER || token.type == PsysLexer::STRING || token.type == PsysLexer::IDENT ||
           token.text == ")" || token.text == "true" || token.text == "false";
}

// Keywords that a `(` follows without a space, as a call's name does.
bool takesArguments(const Atom& token) {
    // (A string before `(` is an event's name: `notify "hit"(pos)`.)
    return token.type == PsysLexer::IDENT || token.type == PsysLexer::STRING || token.text == "point" || token.text == "sprite" ||
           token.text == "streak" || token.text == "trail" || token.text == "range";
}

// A place a line may be broken: after a comma or a binary operator.
struct Break {
    size_t at;        // in Line::code, after the token
    int depth;        // brackets open there
    int rank;         // `=` 0, a comma 1, then the operators by precedence, loosest first
    long open;        // in Line::code, the innermost bracket still open there (-1: opened on an earlier line)
    int level;        // a continuation's level where that bracket opened on an earlier line
};

struct Line {
    int level = 0;
    std::string code;
    std::string comment;  // a trailing `//` comment
    bool blankBefore = false;
    std::vector<Break> breaks;
    std::vector<long> opens;  // in `code`, the brackets open (positions of their `(`)
};

// `line` as lines no longer than `width`, each with its start in the line's code.
std::vector<std::pair<size_t, Line>> fitted(const Line& line, int width);

class Layout {
public:
    explicit Layout(int width) : width_(width) {}

    void add(const Atom& atom) {
        int brk = lineBreak(atom);
        if (brk > 0) {
            fitLast();
            startLine(atom, brk == 2);
        }
        Line& line = lines_.back();
        if (atom.kind == Kind::LineComment && !line.code.empty()) {
            line.comment = atom.text;
        } else {
            if (!line.code.empty() && spaced(atom)) line.code += ' ';
            if (atom.kind == Kind::BlockComment) {
                // Its column: after the code on its line (the last line of it, where an
                // earlier comment spans several).
                size_t lastBreak = line.code.rfind('\n');
                int column = lastBreak == std::string::npos
                                 ? 4 * line.level + static_cast<int>(displayWidth(line.code))
                                 : static_cast<int>(displayWidth(std::string_view(line.code).substr(lastBreak + 1)));
                line.code += reindented(atom, column);
            }
            else
                line.code += atom.text;
        }
        if (atom.kind == Kind::Token) {
            int rank = breaksAfter(atom);
            track(atom);
            if (isToken(&atom, "(")) {
                line.opens.push_back(static_cast<long>(line.code.size()) - 1);
                brackets_.back().at = line.opens.back();
            }
            else if (isToken(&atom, ")") && !line.opens.empty()) line.opens.pop_back();
            if (rank >= 0 && !brackets_.empty() && !boundary_)
                line.breaks.push_back({line.code.size(), static_cast<int>(brackets_.size()), rank,
                                       line.opens.empty() ? -1 : line.opens.back(), brackets_.back().lineLevel + 1});
            else if (rank >= 0 && !boundary_)
                line.breaks.push_back({line.code.size(), 0, rank, -1, statementLevel_ + 1});
        }
        previous_ = &atom;
    }

    // Fits the last line (the others are fitted as the next begins).
    void finish() { fitLast(); }
    std::string text() const;

private:
    struct Open {
        int lineLevel;
        int questions = 0;  // `?` waiting for their `:`
        size_t line = 0;    // where the `(` is: lines_'s index, and its place in the line's code
        long at = -1;
    };

    // 0: on this line; 1: on the next; 2: after a blank line.
    int lineBreak(const Atom& atom) const {
        if (!previous_) return 1;
        int blank = atom.newlinesBefore >= 2 ? 2 : 1;
        if (previous_->kind == Kind::LineComment) return blank;
        if (atom.kind != Kind::Token) return atom.newlinesBefore == 0 ? 0 : (boundary_ ? blank : 1);
        if (isToken(&atom, "}")) return isToken(previous_, "{") ? 0 : 1;
        if (isToken(&atom, "{")) return 0;
        if (isToken(lastToken_, "{")) return 1;
        if (lastToken_ && lastToken_->endsAttribute && !isToken(&atom, ";")) return blank;
        if (boundary_) return blank;
        return atom.newlinesBefore > 0 ? 1 : 0;
    }

    void startLine(const Atom& atom, bool blankBefore) {
        Line line;
        line.blankBefore = blankBefore && !lines_.empty();
        bool statement = boundary_ || (lastToken_ && lastToken_->endsAttribute);
        if (isToken(&atom, "}")) line.level = level_ - 1;
        else if (statement || isToken(&atom, "{")) line.level = statement ? level_ : statementLevel_;
        else if (isToken(&atom, ")") && !brackets_.empty()) line.level = brackets_.back().lineLevel;
        else line.level = (brackets_.empty() ? statementLevel_ : brackets_.back().lineLevel) + 1;
        lines_.push_back(std::move(line));
    }

    bool spaced(const Atom& atom) const {
        if (previous_->kind != Kind::Token || atom.kind != Kind::Token) return true;
        const Atom& prev = *previous_;
        if (isToken(&prev, "(") || isToken(&prev, ".") || isToken(&prev, "@") || prevUnary_) return false;
        if (isToken(&prev, "{") && isToken(&atom, "}")) return false;
        if (isToken(&atom, ")") || isToken(&atom, ",") || isToken(&atom, ";") || isToken(&atom, ".")) return false;
        if (isToken(&atom, "(")) return !takesArguments(prev);
        if (isToken(&atom, ":")) return questionsWaiting() > 0;
        return true;
    }

    int questionsWaiting() const { return brackets_.empty() ? questions_ : brackets_.back().questions; }

    // After a statement's `=`, a comma or a binary operator (not a sign, not `.`, not a
    // fn's `->` before its result type) a line may be broken: its rank (`=` 0, a comma 1,
    // then the operators from the loosest), or -1.
    int breaksAfter(const Atom& token) const {
        if (token.type == PsysLexer::STRING) return -1;
        static constexpr std::string_view kRanked[][4] = {{"="}, {","}, {"->"}, {"?", ":"}, {"||"}, {"&&"}, {"==", "!="},
                                                          {"<", "<=", ">", ">="}, {"+", "-"}, {"*", "/", "%"}};
        int rank = -1;
        for (int r = 0; r < static_cast<int>(std::size(kRanked)) && rank < 0; ++r)
            for (std::string_view op : kRanked[r])
                if (!op.empty() && op == token.text) rank = r;
        if (rank < 0) return -1;
        if (token.text == "-" || token.text == "+") return lastToken_ && endsOperand(*lastToken_) ? rank : -1;  // not a sign
        if (token.text == ":") return questionsWaiting() > 0 ? rank : -1;  // a ternary's, not a type's
        if (token.text == "->") return sawEquals_ ? rank : -1;  // `init -> next`, not `fn f() -> T`
        return rank;
    }

    void track(const Atom& token) {
        bool statementStart = boundary_ || (lastToken_ && lastToken_->endsAttribute);
        if (statementStart) statementLevel_ = level_;
        boundary_ = false;
        prevUnary_ = isToken(&token, "!") ||
                     ((isToken(&token, "-") || isToken(&token, "+")) && !(lastToken_ && endsOperand(*lastToken_)));
        int& questions = brackets_.empty() ? questions_ : brackets_.back().questions;
        if (isToken(&token, "?")) ++questions;
        else if (isToken(&token, ":") && questions > 0) --questions;
        else if (isToken(&token, "(")) brackets_.push_back({lines_.back().level, 0, lines_.size() - 1, -1});
        else if (isToken(&token, ")") && !brackets_.empty()) brackets_.pop_back();
        else if (isToken(&token, "{")) ++level_, boundary_ = true;
        else if (isToken(&token, "}")) level_ = std::max(0, level_ - 1), boundary_ = true;
        else if (isToken(&token, ";")) boundary_ = true;
        else if (isToken(&token, "=")) sawEquals_ = true;
        if (boundary_) brackets_.clear(), questions_ = 0, sawEquals_ = false;
        lastToken_ = &token;
    }

    std::vector<Line> lines_;
    const Atom* previous_ = nullptr;
    const Atom* lastToken_ = nullptr;
    bool boundary_ = true;  // the next token starts a statement
    bool prevUnary_ = false;
    bool sawEquals_ = false;  // the statement's `=` is behind: an expression follows
    int width_;

    // The last line broken where it is too long; the brackets still open in it then belong
    // to the piece that holds them: a continuation line after it is indented past that
    // piece (as when the file is formatted again, with the pieces as its lines).
    void fitLast() {
        if (lines_.empty()) return;
        size_t index = lines_.size() - 1;
        std::vector<std::pair<size_t, Line>> pieces = fitted(lines_.back(), width_);
        if (pieces.size() == 1) return;
        for (Open& open : brackets_) {
            if (open.line != index || open.at < 0) continue;
            for (const auto& [start, piece] : pieces)
                if (static_cast<size_t>(open.at) >= start) open.lineLevel = piece.level;
        }
        lines_.pop_back();
        for (auto& [start, piece] : pieces) lines_.push_back(std::move(piece));
        for (Open& open : brackets_)
            if (open.line == index) open.line = SIZE_MAX;  // (its level is settled)
    }
    int level_ = 0;
    int statementLevel_ = 0;
    int questions_ = 0;
    std::vector<Open> brackets_;
};

// `line` as lines no longer than `width` (where it can be broken): each break is one whose
// first part fits, one whose rest fits too where there is one, then at the shallowest
// bracket depth, a statement's `=` before a comma, a comma before an operator and a loose
// operator before a tight one, the rightmost of those.
std::vector<std::pair<size_t, Line>> fitted(const Line& line, int width) {
    auto length = [](const Line& l) { return 4 * static_cast<size_t>(l.level) + displayWidth(l.code); };
    if (width <= 0 || line.breaks.empty() || line.code.find('\n') != std::string::npos ||
        length(line) + (line.comment.empty() ? 0 : line.comment.size() + 2) <= static_cast<size_t>(width))
        return {{0, line}};
    std::vector<std::pair<size_t, Line>> out;
    std::vector<std::pair<size_t, int>> pieces;  // each piece's start in `code` and its level
    pieces.push_back({0, line.level});
    size_t start = 0;
    auto levelAt = [&](const Break& b) {
        if (b.open < 0) return b.level;
        int level = line.level;  // the level of the piece that holds the bracket
        for (auto [at, l] : pieces)
            if (static_cast<size_t>(b.open) >= at) level = l;
        return level + 1;
    };
    for (;;) {
        int indent = 4 * pieces.back().second;
        if (indent + displayWidth(std::string_view(line.code).substr(start)) <= static_cast<size_t>(width)) break;
        // A break whose rest fits on the next line first (two lines, not three).
        const Break* best = nullptr;
        bool bestRestFits = false;
        for (const Break& b : line.breaks) {
            if (b.at <= start || b.at >= line.code.size()) continue;
            bool fits = indent + displayWidth(std::string_view(line.code).substr(start, b.at - start)) <= static_cast<size_t>(width);
            if (!fits) break;
            bool restFits = 4 * static_cast<size_t>(levelAt(b)) + displayWidth(std::string_view(line.code).substr(b.at)) <=
                            static_cast<size_t>(width) + 1;  // (+1: the space after the break goes)
            auto key = [](const Break& x) { return std::pair(x.depth, x.rank); };
            bool better = !best || (restFits && !bestRestFits) ||
                          (restFits == bestRestFits && (key(b) < key(*best) || (key(b) == key(*best) && b.at > best->at)));
            if (better) best = &b, bestRestFits = restFits;
        }
        if (!best)  // nothing fits: the first break after `start`, so the rest is shorter
            for (const Break& b : line.breaks)
                if (b.at > start && b.at < line.code.size()) {
                    best = &b;
                    break;
                }
        if (!best) break;
        size_t next = best->at;
        while (next < line.code.size() && line.code[next] == ' ') ++next;
        pieces.push_back({next, levelAt(*best)});
        start = next;
    }
    for (size_t i = 0; i < pieces.size(); ++i) {
        Line piece;
        piece.level = pieces[i].second;
        size_t end = i + 1 < pieces.size() ? pieces[i + 1].first : line.code.size();
        piece.code = line.code.substr(pieces[i].first, end - pieces[i].first);
        while (!piece.code.empty() && piece.code.back() == ' ') piece.code.pop_back();
        piece.blankBefore = i == 0 && line.blankBefore;
        if (i + 1 == pieces.size()) piece.comment = line.comment;
        out.push_back({pieces[i].first, std::move(piece)});
    }
    return out;
}

std::string Layout::text() const {
    const std::vector<Line>& lines = lines_;
    // Trailing comments of consecutive lines start in one column.
    std::vector<size_t> column(lines.size(), 0);
    for (size_t i = 0; i < lines.size();) {
        size_t j = i, widest = 0;
        while (j < lines.size() && !lines[j].comment.empty() && lines[j].code.find('\n') == std::string::npos &&
               (j == i || !lines[j].blankBefore)) {
            widest = std::max(widest, 4 * static_cast<size_t>(lines[j].level) + displayWidth(lines[j].code));
            ++j;
        }
        for (size_t k = i; k < j; ++k) column[k] = widest + 2;
        i = std::max(j, i + 1);
    }
    std::string out;
    for (size_t i = 0; i < lines.size(); ++i) {
        const Line& line = lines[i];
        if (line.blankBefore) out += '\n';
        std::string text(4 * static_cast<size_t>(line.level), ' ');
        text += line.code;
        if (!line.comment.empty()) {
            size_t used = displayWidth(text);
            text += std::string(column[i] > used ? column[i] - used : 2, ' ');
            text += line.comment;
        }
        out += text;
        out += '\n';
    }
    return out;
}

bool sameAtoms(const std::vector<Atom>& a, const std::vector<Atom>& b) {
    return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](const Atom& x, const Atom& y) {
               return x.kind == y.kind && x.type == y.type && comparable(x) == comparable(y);
           });
}

// Where the layout `out` of `text` differs from it, widened to whole top-level declarations
// of `out` (each lexes alone: frontend/parse_cache.h): [begin, outEnd) of `out`, the same
// text as [begin, textEnd) of `text` but for white space where the layout is right.
struct Changed {
    size_t begin, outEnd, textEnd;
};

Changed changedDeclarations(const std::string& text, const std::string& out) {
    size_t n = std::min(text.size(), out.size()), same = 0, sameEnd = 0;
    while (same < n && text[same] == out[same]) ++same;
    while (sameEnd < n - same && text[text.size() - 1 - sameEnd] == out[out.size() - 1 - sameEnd]) ++sameEnd;
    Changed c{0, out.size(), text.size()};
    for (const TopDeclaration& d : topLevelDeclarations(out)) {
        if (d.end <= same) {
            c.begin = d.end;
        } else if (d.end >= out.size() - sameEnd && !d.unfinished) {
            c.outEnd = d.end;
            break;
        }
    }
    c.textEnd = text.size() - (out.size() - c.outEnd);
    return c;
}

// Of a text's tokens, those in [begin, end), from `begin`.
std::vector<LexedToken> tokensBetween(const std::vector<LexedToken>& tokens, size_t begin, size_t end) {
    std::vector<LexedToken> inside;
    for (const LexedToken& t : tokens)
        if (t.begin >= begin && t.end <= end)
            inside.push_back({t.type, static_cast<uint32_t>(t.begin - begin), static_cast<uint32_t>(t.end - begin)});
    return inside;
}

}  // namespace

std::optional<std::string> formatSource(int file, const SourceManager& sources, DiagnosticEngine& diags,
                                        const LayoutOptions& options) {
    if (!options.parses && !options.tokens && !parseModule(file, sources, diags)) return std::nullopt;
    // A UTF-8 byte order mark stays where the file had it, outside the layout (as a token
    // it came out of the layout elsewhere, and formatting refused the file).
    const std::string& whole = sources.file(file).text();
    bool marked = whole.rfind(kByteOrderMark, 0) == 0;
    std::string text = marked ? whole.substr(kByteOrderMark.size()) : whole;
    const std::vector<LexedToken>* tokens = options.tokens && !marked ? options.tokens : nullptr;
    std::optional<std::vector<LexedToken>> lexed;
    if (!tokens) {
        lexed = lex(text);
        if (!lexed) return std::nullopt;  // the parser has reported the character
        tokens = &*lexed;
    }
    std::vector<Atom> atoms = atomsOf(text, *tokens);
    Layout layout(options.width);
    for (const Atom& atom : atoms) layout.add(atom);
    layout.finish();
    std::string out = layout.text();
    // (A file already laid out, formatted again on save, is its own text: the same tokens.)
    if (out == text) return whole;
    // The check: the layout's tokens and comments are the text's, where it changed it (the
    // declarations around the first and the last change; lexing 20,000 lines takes a while).
    Changed changed = changedDeclarations(text, out);
    std::string was = text.substr(changed.begin, changed.textEnd - changed.begin),
                part = out.substr(changed.begin, changed.outEnd - changed.begin);
    auto again = lex(part);
    if (!again ||
        !sameAtoms(atomsOf(was, tokensBetween(*tokens, changed.begin, changed.textEnd)), atomsOf(part, *again))) {
        diags.error({file, 0, 0}, "internal error: formatting would change the tokens of this file; it is left as it "
                                  "is (please report it)");
        return std::nullopt;
    }
    return marked ? std::string(kByteOrderMark) + out : out;
}

}  // namespace psys
