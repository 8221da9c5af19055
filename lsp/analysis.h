// One document as the front end sees it: its diagnostics, and an index of what every
// name and expression in it is (for hover, go to definition, symbols and completion).
// The AST is not kept: the index holds what the features need, so an analysis outlives
// the text it came from (completion keeps using the last one that parsed while the
// current text does not).
#pragma once

#include <atomic>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "frontend/diagnostics.h"
#include "frontend/loader.h"
#include "frontend/parse_cache.h"
#include "frontend/source.h"

namespace psys::lsp {

// The protocol's kinds (SymbolKind and CompletionItemKind), the ones used here.
enum class SymbolKind { Class = 5, Property = 7, Field = 8, Function = 12, Variable = 13, Constant = 14, Event = 24 };
enum class CompletionKind { Function = 3, Field = 5, Variable = 6, Class = 7, Property = 10, Keyword = 14,
                            Snippet = 15, Constant = 21, Struct = 22, Event = 23, TypeParameter = 25 };

// Semantic tokens (textDocument/semanticTokens): what a name is, so an editor colours an
// equation, a parameter, a live read of a parent, an extern and a trigger each its own
// way. The types in the legend's order, and the modifiers as bits.
enum class TokenType { None = -1, Variable, Parameter, Property, Function, Class, Macro, Event, EnumMember, Decorator };
inline constexpr const char* kTokenTypes[] = {"variable", "parameter", "property", "function", "class",
                                              "macro", "event", "enumMember", "decorator"};
enum TokenModifier : unsigned { kDeclaration = 1, kReadonly = 2, kDefaultLibrary = 4 };
inline constexpr const char* kTokenModifiers[] = {"declaration", "readonly", "defaultLibrary"};

struct Token {
    TokenType type = TokenType::None;
    unsigned modifiers = 0;
};

// A name or expression in a file: what hover shows, where its declaration is, and (a
// name) what kind of name it is.
struct Occurrence {
    SourceRange range;
    // Markdown (shared: an analysis moved through an edit copies 100,000 occurrences)
    std::shared_ptr<const std::string> hover;
    std::optional<SourceRange> definition;
    Token token;
};

struct Symbol {
    std::string name, detail;
    SymbolKind kind;
    SourceRange range, selection;
    std::vector<Symbol> children;
};

// A note the editor shows inside the text (textDocument/inlayHint): an equation's or a
// let's inferred type after its name, the integrator and step an object runs with.
struct Hint {
    SourceRange at;  // shown at at.end
    std::string label;
    int kind;        // the protocol's InlayHintKind: 1 a type, 2 a parameter (the method)
};

struct Name {
    std::string label, detail, documentation;
    CompletionKind kind;
};

// Names visible inside a range of the main file beyond the file scope: an object's
// parameters, equations, nested objects and enclosing objects; a fn's parameters and lets;
// a trigger's parameters.
struct Scope {
    SourceRange range;
    std::vector<Name> names;
    bool pure = false;  // a fn's body: no history, no age or time, no externs or objects
};

// An editor lists every error a file has, up to this many (and as many warnings); past
// that, a note at the top of the file says how many more there are. 50,000 errors of a
// broken generated file would be megabytes of JSON on every keystroke.
constexpr int kMaxPublished = 1000;
// An analysis keeps every front-end diagnostic up to this many (for the next text's
// analysis to carry: lsp/incremental.h); past it, the next is a whole one.
constexpr int kMaxKept = 10 * kMaxPublished;

// Where one of the main file's top-level declarations' entries start in an analysis's
// index (buildIndex walks the imports', then the main file's declarations in order).
struct IndexMark {
    uint32_t begin = 0;  // the declaration's first byte (the end of the file: past the last)
    size_t occurrences = 0, symbols = 0, globals = 0, scopes = 0, hints = 0, integrating = 0, members = 0;
};

struct Analysis {
    std::unique_ptr<SourceManager> sources;
    int mainFile = -1;
    bool parsed = false;  // false: syntax errors (or no file); only the diagnostics are meaningful
    // The index of an older text that parsed, moved into this one around the edit since
    // (lsp/recover.h): this text has syntax errors, `diagnostics` are its own.
    bool recovered = false;
    double milliseconds = 0;  // how long the analysis took
    // The compiler's passes ran (a clean front end, AnalyzeOptions::passes), taking this
    // long; their warnings are diagnostics[passDiagnostics…] and their hints (each
    // object's method) hints[passHints…]. An analysis without them may hold the last
    // ones carried through the edits since (carryPasses, lsp/recover.h): the same places.
    bool passesRan = false;
    double passesMs = 0;
    size_t passDiagnostics = 0, passHints = 0;
    // The front end's (in the order of their places) then the passes': at most
    // kMaxPublished errors and as many warnings, the first in the file.
    std::vector<Diagnostic> diagnostics;
    int hiddenErrors = 0, hiddenWarnings = 0;  // counted past that, not kept
    std::vector<Occurrence> occurrences;  // every file's, in the order found
    std::vector<Symbol> symbols;          // the main file's declarations
    std::vector<Name> globals;            // the file scope: every module's declarations
    std::vector<Scope> scopes;
    std::vector<Hint> hints;              // the main file's
    std::vector<SourceRange> integrating;  // the main file's objects that integrate (name ranges)
    std::vector<std::pair<std::string, std::vector<Name>>> members;  // per object: what `object.` reads
    // The files the main file imports, directly or not (their sourceKey): an edit to one of
    // them, open in the editor, calls for this document to be analysed again.
    std::set<std::string> imported;

    // For the analysis of the next text to re-check only what its edit touched
    // (lsp/incremental.h): the main file's pieces as parsed (ParseCache::pieces), each of
    // its declarations' first index entries (and one past the last), every front-end
    // diagnostic (null where there were more than kMaxKept), whether the program reads
    // `instance`; and whether this analysis was made so.
    std::vector<PieceAt> pieces;
    std::vector<IndexMark> marks;
    std::shared_ptr<const std::vector<Diagnostic>> frontEnd;
    bool instanced = false;
    bool incremental = false;

    // The innermost occurrence at `offset` of `file` (its end counts: the cursor just after a name).
    const Occurrence* at(int file, uint32_t offset) const;
};

struct AnalyzeOptions {
    // When given and set (from another thread) while it runs, the analysis stops early
    // between its phases; what it returns then is incomplete and only to be thrown away.
    const std::atomic<bool>* cancelled = nullptr;
    // Imports are read from here where it has their text (the editor's documents), else from disk.
    const SourceOverrides* open = nullptr;
    // Where the text has syntax errors, the index is that of the text with its broken
    // top-level declarations blanked (lsp/salvage.h), marked `recovered` (a second
    // analysis: for a file with no earlier text that parsed to recover from).
    bool salvage = false;
    // The compiler's passes (their warnings, the methods' hints) after a clean front end:
    // not for the workspace index, which needs names and places only.
    bool passes = true;
    // Where given, the files are parsed through it (frontend/parse_cache.h): a document's
    // analysis after an edit parses only the declarations the edit changed.
    ParseCache* cache = nullptr;
    // Where given (with `cache`, and without the passes), the last analysis of the
    // document that parsed: only the declarations the edit since can change are checked
    // again where that is enough (lsp/incremental.h).
    const Analysis* previous = nullptr;
};

// Runs the front end over `text` as the file `path` (imports are read relative to it),
// and the compiler's passes when it is clean, for their warnings.
Analysis analyze(const std::string& path, std::string text, const AnalyzeOptions& options = {});
// The salvage of `broken` (AnalyzeOptions::salvage), nullopt where it cannot help.
std::optional<Analysis> salvaged(const std::string& path, const Analysis& broken, const AnalyzeOptions& options);

}  // namespace psys::lsp
