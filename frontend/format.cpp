// The canonical layout works on the token stream, not the AST, so that every comment stays
// where the author put it and nothing the parser drops can be lost: the output has the
// same tokens as the input, only the white space between them changes.
//
// Structure fixes the line breaks (one statement a line, blocks opened at the end of a
// line and closed on one of their own, each object attribute on a line); inside a
// statement the author's line breaks stay, and the continuation lines are indented one
// level past the line that opened the innermost bracket still open. Blank lines are kept
// (at most one) between statements. Trailing comments on consecutive lines line up.
#include "frontend/format.h"

#include <algorithm>
#include <string_view>
#include <vector>

#include <antlr4-runtime.h>

#include "PsysLexer.h"
#include "frontend/parse.h"

namespace psys {
namespace {

using grammar::PsysLexer;

enum class Kind { Token, LineComment, BlockComment };

struct Atom {
    Kind kind = Kind::Token;
    int type = 0;  // the lexer's token type
    std::string text;
    int newlinesBefore = 0;  // in the source, between the previous atom and this one
    bool endsAttribute = false;
};

bool isToken(const Atom* atom, std::string_view text) {
    return atom && atom->kind == Kind::Token && atom->type != PsysLexer::STRING && atom->text == text;
}

// Newlines, `//` and `/* */` comments in the text between two tokens (the lexer skips them).
void addGap(std::string_view gap, std::vector<Atom>& atoms, int& newlines) {
    for (size_t i = 0; i < gap.size();) {
        if (gap.compare(i, 2, "//") == 0) {
            size_t end = gap.find('\n', i);
            if (end == std::string_view::npos) end = gap.size();
            std::string_view text = gap.substr(i, end - i);
            while (!text.empty() && (text.back() == ' ' || text.back() == '\t' || text.back() == '\r'))
                text.remove_suffix(1);
            atoms.push_back({Kind::LineComment, 0, std::string(text), newlines, false});
            newlines = 0;
            i = end;
        } else if (gap.compare(i, 2, "/*") == 0) {
            size_t end = gap.find("*/", i + 2);
            end = end == std::string_view::npos ? gap.size() : end + 2;
            atoms.push_back({Kind::BlockComment, 0, std::string(gap.substr(i, end - i)), newlines, false});
            newlines = 0;
            i = end;
        } else {
            if (gap[i] == '\n') ++newlines;
            ++i;
        }
    }
}

// The tokens and comments of `text` in order. Null when the lexer meets a character the
// language does not have.
std::optional<std::vector<Atom>> atomsOf(const std::string& text) {
    antlr4::ANTLRInputStream input(text);
    PsysLexer lexer(&input);
    lexer.removeErrorListeners();
    std::vector<uint32_t> offsets = codePointOffsets(text);
    std::vector<Atom> atoms;
    uint32_t at = 0;
    int newlines = 0;
    for (const auto& token : lexer.getAllTokens()) {
        if (token->getType() == PsysLexer::UNKNOWN_CHAR) return std::nullopt;
        uint32_t begin = offsets[token->getStartIndex()], end = offsets[token->getStopIndex() + 1];
        addGap(std::string_view(text).substr(at, begin - at), atoms, newlines);
        atoms.push_back({Kind::Token, static_cast<int>(token->getType()), text.substr(begin, end - begin), newlines,
                         false});
        newlines = 0;
        at = end;
    }
    addGap(std::string_view(text).substr(at), atoms, newlines);
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

size_t displayWidth(std::string_view text) {
    return static_cast<size_t>(
        std::count_if(text.begin(), text.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; }));
}

struct Line {
    int level = 0;
    std::string code;
    std::string comment;  // a trailing `//` comment
    bool blankBefore = false;
};

class Layout {
public:
    void add(const Atom& atom) {
        int brk = lineBreak(atom);
        if (brk > 0) startLine(atom, brk == 2);
        Line& line = lines_.back();
        if (atom.kind == Kind::LineComment && !line.code.empty()) {
            line.comment = atom.text;
        } else {
            if (!line.code.empty() && spaced(atom)) line.code += ' ';
            line.code += atom.text;
        }
        if (atom.kind == Kind::Token) track(atom);
        previous_ = &atom;
    }

    std::string text() const;

private:
    struct Open {
        int lineLevel;
        int questions = 0;  // `?` waiting for their `:`
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

    void track(const Atom& token) {
        bool statementStart = boundary_ || (lastToken_ && lastToken_->endsAttribute);
        if (statementStart) statementLevel_ = level_;
        boundary_ = false;
        prevUnary_ = isToken(&token, "!") ||
                     ((isToken(&token, "-") || isToken(&token, "+")) && !(lastToken_ && endsOperand(*lastToken_)));
        int& questions = brackets_.empty() ? questions_ : brackets_.back().questions;
        if (isToken(&token, "?")) ++questions;
        else if (isToken(&token, ":") && questions > 0) --questions;
        else if (isToken(&token, "(")) brackets_.push_back({lines_.back().level});
        else if (isToken(&token, ")") && !brackets_.empty()) brackets_.pop_back();
        else if (isToken(&token, "{")) ++level_, boundary_ = true;
        else if (isToken(&token, "}")) level_ = std::max(0, level_ - 1), boundary_ = true;
        else if (isToken(&token, ";")) boundary_ = true;
        if (boundary_) brackets_.clear(), questions_ = 0;
        lastToken_ = &token;
    }

    std::vector<Line> lines_;
    const Atom* previous_ = nullptr;
    const Atom* lastToken_ = nullptr;
    bool boundary_ = true;  // the next token starts a statement
    bool prevUnary_ = false;
    int level_ = 0;
    int statementLevel_ = 0;
    int questions_ = 0;
    std::vector<Open> brackets_;
};

std::string Layout::text() const {
    // Trailing comments of consecutive lines start in one column.
    std::vector<size_t> column(lines_.size(), 0);
    for (size_t i = 0; i < lines_.size();) {
        size_t j = i, widest = 0;
        while (j < lines_.size() && !lines_[j].comment.empty() && lines_[j].code.find('\n') == std::string::npos &&
               (j == i || !lines_[j].blankBefore)) {
            widest = std::max(widest, 4 * static_cast<size_t>(lines_[j].level) + displayWidth(lines_[j].code));
            ++j;
        }
        for (size_t k = i; k < j; ++k) column[k] = widest + 2;
        i = std::max(j, i + 1);
    }
    std::string out;
    for (size_t i = 0; i < lines_.size(); ++i) {
        const Line& line = lines_[i];
        if (line.blankBefore) out += '\n';
        std::string text(4 * static_cast<size_t>(line.level), ' ');
        text += line.code;
        if (!line.comment.empty()) {
            size_t width = displayWidth(text);
            text += std::string(column[i] > width ? column[i] - width : 2, ' ');
            text += line.comment;
        }
        out += text;
        out += '\n';
    }
    return out;
}

bool sameAtoms(const std::vector<Atom>& a, const std::vector<Atom>& b) {
    return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](const Atom& x, const Atom& y) {
               return x.kind == y.kind && x.type == y.type && x.text == y.text;
           });
}

}  // namespace

std::optional<std::string> formatSource(int file, const SourceManager& sources, DiagnosticEngine& diags, bool parses) {
    if (!parses && !parseModule(file, sources, diags)) return std::nullopt;
    // A UTF-8 byte order mark stays where the file had it, outside the layout (as a token
    // it came out of the layout elsewhere, and formatting refused the file).
    static const std::string kByteOrderMark = "\xEF\xBB\xBF";
    const std::string& whole = sources.file(file).text();
    bool marked = whole.rfind(kByteOrderMark, 0) == 0;
    std::string text = marked ? whole.substr(kByteOrderMark.size()) : whole;
    auto atoms = atomsOf(text);
    if (!atoms) return std::nullopt;  // the parser has reported the character
    Layout layout;
    for (const Atom& atom : *atoms) layout.add(atom);
    std::string out = layout.text();
    auto again = atomsOf(out);
    if (!again || !sameAtoms(*atoms, *again)) {
        diags.error({file, 0, 0}, "internal error: formatting would change the tokens of this file; it is left as it "
                                  "is (please report it)");
        return std::nullopt;
    }
    return marked ? kByteOrderMark + out : out;
}

}  // namespace psys
