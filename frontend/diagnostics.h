// Diagnostics: collected during a run, printed in the style of a mature compiler:
//
//   fire.psys:12:9: error: cannot add vec3 and vec4
//      12 |     acc = gravity + tint;
//         |           ~~~~~~~~^~~~~~
//   fire.psys:3:1: note: `tint` declared here
//
// Several errors per run; colour only when asked (the driver asks on a terminal).
#pragma once

#include <algorithm>
#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "frontend/source.h"

namespace psys {

// A remark says what the compiler did or found, asked for (`psysc check --remarks`): no fault.
enum class Severity { Error, Warning, Note, Remark };

struct DiagnosticNote {
    SourceRange range;
    std::string message;
};

// The reports on a whole program, made where it has no other error (frontend.h's
// CheckOptions::allReports): the functions and equations too large once inlined, then
// (where none is) the equations never used and the objects never created.
enum class ProgramReport : uint8_t { None, InlinedSize, Unused };

// An edit that does what a diagnostic suggests: the editor offers it as a quick fix.
struct FixIt {
    std::string title;  // what the editor lists: "Change to `vel`"
    SourceRange range;  // the text replaced (empty: an insertion)
    std::string replacement;
};

struct Diagnostic {
    Severity severity = Severity::Error;
    SourceRange range;
    std::string message;
    std::vector<DiagnosticNote> notes;
    std::vector<FixIt> fixes;
    // The byte the caret marks and `line:column` names, inside `range` (nullopt: its
    // start): the operator of a binary expression whose operands' types disagree.
    std::optional<uint32_t> focus;
    ProgramReport report = ProgramReport::None;
};

// Which of the program reports in `all` (a check's with CheckOptions::allReports) a check
// without it makes: the sizes where nothing else is an error, the unused where nothing is.
struct PublishedReports {
    bool inlinedSize = false, unused = false;
    bool operator()(const Diagnostic& d) const {
        return d.report == ProgramReport::None || (d.report == ProgramReport::InlinedSize ? inlinedSize : unused);
    }
};
PublishedReports publishedReports(const std::vector<Diagnostic>& all);

class DiagnosticEngine {
public:
    explicit DiagnosticEngine(const SourceManager& sources) : sources_(sources) {}
    const SourceManager& sources() const { return sources_; }

    // Returns the diagnostic so a caller can attach notes.
    Diagnostic& error(SourceRange range, std::string message);
    Diagnostic& warning(SourceRange range, std::string message);
    Diagnostic& remark(SourceRange range, std::string message);

    // At most `limit()` errors and as many warnings are kept and printed; the rest are
    // counted. A terminal shows 50 (the first is the one to fix); an editor lists more.
    static constexpr int kMaxShown = 50;
    void setLimit(int limit) { limit_ = limit; }
    int limit() const { return limit_; }
    // How many were counted but not kept.
    int hiddenErrors() const { return std::max(0, errors_ - limit_); }
    int hiddenWarnings() const { return std::max(0, warnings_ - limit_); }

    int errorCount() const { return errors_; }
    int warningCount() const { return warnings_; }
    const std::vector<Diagnostic>& all() const { return diagnostics_; }
    // The diagnostics kept, moved out (the engine keeps its counts).
    std::vector<Diagnostic> take() { return std::move(diagnostics_); }

    // While suppressed, reports are dropped (used for trial passes of type inference).
    void setSuppressed(bool suppressed) { suppressed_ = suppressed; }
    bool suppressed() const { return suppressed_; }

    // A diagnostic with no place in a source (a file that cannot be read) is labelled with
    // the program that prints it: `psysc: error: …`, `psys-view: error: …`.
    void setProgram(std::string program) { program_ = std::move(program); }

    void print(std::ostream& out, bool colour) const;
    std::string render(bool colour = false) const;

private:
    Diagnostic& add(Severity severity, SourceRange range, std::string message);

    const SourceManager& sources_;
    std::string program_ = "psysc";
    std::vector<Diagnostic> diagnostics_;
    Diagnostic discarded_;
    int errors_ = 0;
    int warnings_ = 0;
    int remarks_ = 0;
    int limit_ = kMaxShown;
    bool suppressed_ = false;
};

}  // namespace psys
