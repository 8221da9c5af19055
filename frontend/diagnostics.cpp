#include "frontend/diagnostics.h"

#include <algorithm>
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

// Prints `path:line:col: severity: message`, then the source line with the range
// underlined: a caret at its start and tildes over the rest of it on that line.
void printOne(std::ostream& out, const SourceManager& sources, Severity severity,
              SourceRange range, const std::string& message, bool colour, const std::string& program) {
    auto paint = [&](const char* code) { return colour ? code : ""; };
    if (!range.valid()) {
        out << paint(kBold) << program << ": " << paint(kReset) << paint(severityColour(severity))
            << severityWord(severity) << ": " << paint(kReset) << paint(kBold) << message
            << paint(kReset) << '\n';
        return;
    }
    const SourceFile& file = sources.file(range.file);
    LineColumn at = file.lineColumn(range.begin);
    out << paint(kBold) << file.path() << ':' << at.line << ':' << at.column << ": "
        << paint(kReset) << paint(severityColour(severity)) << severityWord(severity) << ": "
        << paint(kReset) << paint(kBold) << message << paint(kReset) << '\n';

    std::string line = printable(file.lineText(at.line));
    std::string number = std::to_string(at.line);
    std::string gutter(number.size(), ' ');

    uint32_t startCol = at.column - 1;
    uint32_t endCol = startCol + 1;
    if (range.end > range.begin) {
        LineColumn last = file.lineColumn(range.end - 1);
        endCol = last.line == at.line ? last.column : static_cast<uint32_t>(line.size());
    }
    endCol = std::max(endCol, startCol + 1);
    // A line of a generated file may be 100,000 characters: show a window of it around the
    // range, marked with `...` where it is cut.
    constexpr uint32_t kBefore = 60, kWidth = 160;
    if (line.size() > kBefore + kWidth) {
        uint32_t from = startCol > kBefore ? startCol - kBefore : 0;
        while (from > 0 && (static_cast<unsigned char>(line[from]) & 0xC0) == 0x80) --from;  // whole characters
        uint32_t to = std::min<uint32_t>(static_cast<uint32_t>(line.size()), from + kWidth);
        while (to < line.size() && (static_cast<unsigned char>(line[to]) & 0xC0) == 0x80) ++to;
        std::string head = from > 0 ? "..." : "", tail = to < line.size() ? "..." : "";
        line = head + line.substr(from, to - from) + tail;
        uint32_t shift = static_cast<uint32_t>(head.size()) - from;
        startCol += shift;
        endCol = std::min(endCol + shift, static_cast<uint32_t>(line.size() - tail.size()));
        endCol = std::max(endCol, startCol + 1);
    }
    out << ' ' << number << " | " << line << '\n';

    // Underline: tabs are copied from the source so the caret lines up.
    std::string marks;
    for (uint32_t i = 0; i < startCol; ++i) marks += (i < line.size() && line[i] == '\t') ? '\t' : ' ';
    std::string underline = "^";
    for (uint32_t i = startCol + 1; i < endCol; ++i) underline += '~';
    out << ' ' << gutter << " | " << marks << paint(kGreen) << underline << paint(kReset) << '\n';
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
    if (count > kMaxShown) {
        discarded_ = {};
        return discarded_;
    }
    diagnostics_.push_back({severity, range, std::move(message), {}, {}});
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
        printOne(out, sources_, d.severity, d.range, d.message, colour, program_);
        for (const DiagnosticNote& n : d.notes)
            printOne(out, sources_, Severity::Note, n.range, n.message, colour, program_);
    }
    int hiddenErrors = std::max(0, errors_ - kMaxShown), hiddenWarnings = std::max(0, warnings_ - kMaxShown);
    if (hiddenErrors > 0 || hiddenWarnings > 0)
        out << fmt::format("(the first {} errors and {} warnings are shown; {} more errors and {} more warnings are not)\n",
                           std::min(errors_, kMaxShown), std::min(warnings_, kMaxShown), hiddenErrors, hiddenWarnings);
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

}  // namespace psys
