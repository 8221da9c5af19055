#include "frontend/diagnostics.h"

#include <algorithm>
#include <optional>
#include <ostream>
#include <sstream>

#include <fmt/format.h>

namespace psys {
namespace {

// A source line as a terminal can show it, byte for byte in place (so the caret lines up):
// control characters become spaces, bytes that are not UTF-8 become '?'.
std::string printable(std::string_view line) {
    std::string out(line);
    for (size_t i = 0; i < out.size();) {
        auto c = static_cast<unsigned char>(out[i]);
        if ((c < 0x20 && c != '\t') || c == 0x7F) out[i] = ' ';
        if (c < 0x80) {
            ++i;
            continue;
        }
        auto bad = firstInvalidUtf8(std::string_view(out).substr(i));
        if (bad && *bad == 0) {
            out[i++] = '?';
            continue;
        }
        ++i;
        while (i < out.size() && (static_cast<unsigned char>(out[i]) & 0xC0) == 0x80) ++i;
    }
    return out;
}

constexpr const char* kReset = "\x1b[0m";
constexpr const char* kBold = "\x1b[1m";
constexpr const char* kRed = "\x1b[1;31m";
constexpr const char* kMagenta = "\x1b[1;35m";
constexpr const char* kCyan = "\x1b[1;36m";
constexpr const char* kGreen = "\x1b[1;32m";

const char* severityWord(Severity s) {
    switch (s) {
        case Severity::Error: return "error";
        case Severity::Warning: return "warning";
        case Severity::Note: return "note";
        case Severity::Remark: return "remark";
    }
    return "error";
}

const char* severityColour(Severity s) {
    switch (s) {
        case Severity::Error: return kRed;
        case Severity::Warning: return kMagenta;
        case Severity::Note: return kCyan;
        case Severity::Remark: return kGreen;
    }
    return kRed;
}

// Terminal cells a code point takes: 2 for East Asian wide characters and emoji, 0 for a
// combining mark, else 1 (enough to keep a caret under its character).
int cells(uint32_t c) {
    if ((c >= 0x300 && c <= 0x36F) || (c >= 0x200B && c <= 0x200F) || c == 0xFE0F) return 0;
    bool wide = (c >= 0x1100 && c <= 0x115F) || (c >= 0x2E80 && c <= 0xA4CF && c != 0x303F) ||
                (c >= 0xAC00 && c <= 0xD7A3) || (c >= 0xF900 && c <= 0xFAFF) || (c >= 0xFE30 && c <= 0xFE4F) ||
                (c >= 0xFF00 && c <= 0xFF60) || (c >= 0xFFE0 && c <= 0xFFE6) || (c >= 0x1F300 && c <= 0x1F64F) ||
                (c >= 0x1F900 && c <= 0x1F9FF) || (c >= 0x20000 && c <= 0x3FFFD);
    return wide ? 2 : 1;
}

// The code point at `line[i]` (printable() has made the line valid UTF-8) and its length.
uint32_t decode(std::string_view line, size_t i, size_t* length) {
    auto c = static_cast<unsigned char>(line[i]);
    size_t n = c < 0x80 ? 1 : c < 0xE0 ? 2 : c < 0xF0 ? 3 : 4;
    n = std::min(n, line.size() - i);
    uint32_t cp = n == 1 ? c : c & (0xFF >> (n + 1));
    for (size_t k = 1; k < n; ++k) cp = (cp << 6) | (static_cast<unsigned char>(line[i + k]) & 0x3F);
    *length = n;
    return cp;
}

// The marks under `line`: spaces (tabs where the line has them) up to byte `from`, then
// `~` over bytes [from, to) and `^` on the character at byte `caret`, a cell per cell.
std::string underline(std::string_view line, uint32_t from, uint32_t to, uint32_t caret) {
    std::string marks;
    size_t length = 1;
    for (size_t i = 0; i < line.size() && i < std::max(to, caret + 1); i += length) {
        int width = cells(decode(line, i, &length));
        if (i < from && i != caret) {
            marks += line[i] == '\t' ? std::string(1, '\t') : std::string(static_cast<size_t>(width), ' ');
        } else {
            marks += i == caret ? '^' : '~';
            if (width > 1) marks += '~';
        }
    }
    if (caret >= line.size()) marks += '^';  // the end of the line
    while (!marks.empty() && marks.back() == ' ') marks.pop_back();
    return marks;
}

// Prints `path:line:col: severity: message` (the column in bytes, as editors jump to it),
// then the source line with the range underlined on the caret's line: a caret at `focus`
// (the range's start unless given) and tildes over the rest of the range.
void printOne(std::ostream& out, const SourceManager& sources, Severity severity, SourceRange range,
              std::optional<uint32_t> focus, const std::string& message, bool colour, const std::string& program) {
    auto paint = [&](const char* code) { return colour ? code : ""; };
    if (!range.valid()) {
        out << paint(kBold) << program << ": " << paint(kReset) << paint(severityColour(severity))
            << severityWord(severity) << ": " << paint(kReset) << paint(kBold) << message
            << paint(kReset) << '\n';
        return;
    }
    const SourceFile& file = sources.file(range.file);
    uint32_t caretAt = focus.value_or(range.begin);
    LineColumn at = file.lineColumn(caretAt);
    out << paint(kBold) << file.path() << ':' << at.line << ':' << at.column << ": "
        << paint(kReset) << paint(severityColour(severity)) << severityWord(severity) << ": "
        << paint(kReset) << paint(kBold) << message << paint(kReset) << '\n';

    std::string line = printable(file.lineText(at.line));
    std::string number = std::to_string(at.line);
    std::string gutter(number.size(), ' ');

    // Byte columns on this line: the caret, and the range clipped to the line.
    uint32_t lineStart = caretAt - (at.column - 1);
    uint32_t caret = at.column - 1;
    uint32_t from = range.begin > lineStart ? range.begin - lineStart : 0;
    uint32_t to = range.end > lineStart ? std::min<uint32_t>(range.end - lineStart, static_cast<uint32_t>(line.size())) : 0;
    from = std::min(from, caret);
    to = std::max(to, caret + 1);
    // A line of a generated file may be 100,000 characters: show a window of it around the
    // caret, marked with `...` where it is cut.
    constexpr uint32_t kBefore = 60, kWidth = 160;
    if (line.size() > kBefore + kWidth) {
        uint32_t begin = caret > kBefore ? caret - kBefore : 0;
        while (begin > 0 && (static_cast<unsigned char>(line[begin]) & 0xC0) == 0x80) --begin;  // whole characters
        uint32_t end = std::min<uint32_t>(static_cast<uint32_t>(line.size()), begin + kWidth);
        while (end < line.size() && (static_cast<unsigned char>(line[end]) & 0xC0) == 0x80) ++end;
        std::string head = begin > 0 ? "..." : "", tail = end < line.size() ? "..." : "";
        line = head + line.substr(begin, end - begin) + tail;
        auto shift = [&](uint32_t x) {
            return std::clamp<uint32_t>(x, begin, end) - begin + static_cast<uint32_t>(head.size());
        };
        caret = shift(caret), from = shift(from), to = std::max(shift(to), caret + 1);
    }
    out << ' ' << number << " | " << line << '\n';
    out << ' ' << gutter << " | " << paint(kGreen) << underline(line, from, to, caret) << paint(kReset) << '\n';
}

}  // namespace

Diagnostic& DiagnosticEngine::add(Severity severity, SourceRange range, std::string message) {
    if (suppressed_) {
        discarded_ = {};
        return discarded_;
    }
    int& count = severity == Severity::Error ? errors_ : severity == Severity::Remark ? remarks_ : warnings_;
    ++count;
    // Past the limit they are counted, not kept: 50,000 errors of a broken generated file
    // would bury the first, which is the one to fix.
    if (count > limit_) {
        discarded_ = {};
        return discarded_;
    }
    diagnostics_.push_back({severity, range, std::move(message), {}, {}, std::nullopt});
    return diagnostics_.back();
}

Diagnostic& DiagnosticEngine::remark(SourceRange range, std::string message) {
    return add(Severity::Remark, range, std::move(message));
}

Diagnostic& DiagnosticEngine::error(SourceRange range, std::string message) {
    return add(Severity::Error, range, std::move(message));
}

Diagnostic& DiagnosticEngine::warning(SourceRange range, std::string message) {
    return add(Severity::Warning, range, std::move(message));
}

void DiagnosticEngine::print(std::ostream& out, bool colour) const {
    for (const Diagnostic& d : diagnostics_) {
        printOne(out, sources_, d.severity, d.range, d.focus, d.message, colour, program_);
        for (const DiagnosticNote& n : d.notes)
            printOne(out, sources_, Severity::Note, n.range, std::nullopt, n.message, colour, program_);
    }
    if (hiddenErrors() > 0 || hiddenWarnings() > 0) {
        // Only the kinds there are: "the first 50 warnings are shown; 2449 more warnings are not".
        auto count = [](int n, const char* more, const char* what) {
            return fmt::format("{} {}{}{}", n, more, what, n == 1 ? "" : "s");
        };
        auto both = [](std::vector<std::string> parts) {
            return parts.size() == 2 ? parts[0] + " and " + parts[1] : parts[0];
        };
        std::vector<std::string> shown, hidden;
        if (errors_ > 0) shown.push_back(count(std::min(errors_, limit_), "", "error"));
        if (warnings_ > 0) shown.push_back(count(std::min(warnings_, limit_), "", "warning"));
        if (hiddenErrors() > 0) hidden.push_back(count(hiddenErrors(), "more ", "error"));
        if (hiddenWarnings() > 0) hidden.push_back(count(hiddenWarnings(), "more ", "warning"));
        out << fmt::format("(the first {} {} shown; {} {} not)\n", both(shown),
                           shown.size() == 1 && std::min(errors_ + warnings_, limit_) == 1 ? "is" : "are", both(hidden),
                           hidden.size() == 1 && hiddenErrors() + hiddenWarnings() == 1 ? "is" : "are");
    }
    if (errors_ > 0 || warnings_ > 0) {
        std::vector<std::string> parts;
        if (errors_ > 0) parts.push_back(fmt::format("{} error{}", errors_, errors_ == 1 ? "" : "s"));
        if (warnings_ > 0)
            parts.push_back(fmt::format("{} warning{}", warnings_, warnings_ == 1 ? "" : "s"));
        out << (parts.size() == 2 ? parts[0] + " and " + parts[1] : parts[0]) << " generated.\n";
    }
}

std::string DiagnosticEngine::render(bool colour) const {
    std::ostringstream out;
    print(out, colour);
    return out.str();
}

PublishedReports publishedReports(const std::vector<Diagnostic>& all) {
    bool placeErrors = false, sizeErrors = false;
    for (const Diagnostic& d : all) {
        if (d.severity != Severity::Error) continue;
        placeErrors |= d.report == ProgramReport::None;
        sizeErrors |= d.report == ProgramReport::InlinedSize;
    }
    return {!placeErrors, !placeErrors && !sizeErrors};
}

}  // namespace psys
