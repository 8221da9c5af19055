// The shape of a file and of the workspace: folding ranges (declarations over several
// lines, block comments, runs of line comments), symbols across the open documents, and
// signature help for the call around the cursor.
#include <algorithm>
#include <cctype>

#include "frontend/builtins.h"
#include "lsp/features.h"
#include "lsp/positions.h"

namespace psys::lsp {

using nlohmann::json;

namespace {

void foldSymbols(const SourceFile& f, const std::vector<Symbol>& symbols, json& out) {
    for (const Symbol& s : symbols) {
        uint32_t first = f.lineColumn(s.range.begin).line, last = f.lineColumn(s.range.end).line;
        if (last > first) out.push_back({{"startLine", first - 1}, {"endLine", last - 1}, {"kind", "region"}});
        foldSymbols(f, s.children, out);
    }
}

// Block comments over several lines and runs of two or more `//` lines; strings skipped.
void foldComments(const SourceFile& f, json& out) {
    const std::string& t = f.text();
    uint32_t runFirst = 0, runLast = 0;
    bool inRun = false;
    auto endRun = [&] {
        if (inRun && runLast > runFirst) out.push_back({{"startLine", runFirst - 1}, {"endLine", runLast - 1}, {"kind", "comment"}});
        inRun = false;
    };
    for (size_t i = 0; i < t.size(); ++i) {
        if (t[i] == '"') {
            size_t close = t.find_first_of("\"\n", i + 1);
            i = close == std::string::npos ? t.size() : close;
        } else if (t.compare(i, 2, "/*") == 0) {
            size_t close = t.find("*/", i + 2);
            size_t end = close == std::string::npos ? t.size() : close + 2;
            uint32_t a = f.lineColumn(static_cast<uint32_t>(i)).line, b = f.lineColumn(static_cast<uint32_t>(end)).line;
            if (b > a) out.push_back({{"startLine", a - 1}, {"endLine", b - 1}, {"kind", "comment"}});
            i = end - 1;
        } else if (t.compare(i, 2, "//") == 0) {
            LineColumn at = f.lineColumn(static_cast<uint32_t>(i));
            bool alone = f.lineText(at.line).find_first_not_of(" \t") == at.column - 1;  // nothing before it
            if (alone && inRun && at.line == runLast + 1) runLast = at.line;
            else {
                endRun();
                if (alone) inRun = true, runFirst = runLast = at.line;
            }
            size_t eol = t.find('\n', i);
            i = eol == std::string::npos ? t.size() : eol;
        }
    }
    endRun();
}

void flatten(const std::vector<Symbol>& symbols, const std::string& container, const std::string& query,
             const SourceFile& f, json& out) {
    auto matches = [&](const std::string& name) {  // the query's letters in order, any case
        size_t k = 0;
        for (char c : name)
            if (k < query.size() && std::tolower(static_cast<unsigned char>(c)) == std::tolower(static_cast<unsigned char>(query[k]))) ++k;
        return k == query.size();
    };
    for (const Symbol& s : symbols) {
        if (matches(s.name)) {
            json j = {{"name", s.name},
                      {"kind", static_cast<int>(s.kind)},
                      {"location", {{"uri", uriFromPath(f.path())}, {"range", range(f, s.selection.begin, s.selection.end)}}}};
            if (!container.empty()) j["containerName"] = container;
            out.push_back(j);
        }
        flatten(s.children, s.name, query, f, out);
    }
}

// The parameters of a signature's text ("fn f(a: float, b: vec3) -> float",
// "clamp(x: T, lo: T|float, hi: T|float) -> T"): each one's [start, end) in it.
std::vector<std::pair<size_t, size_t>> parameterSpans(const std::string& label) {
    std::vector<std::pair<size_t, size_t>> spans;
    size_t open = label.find('(');
    if (open == std::string::npos) return spans;
    int depth = 0;
    size_t start = open + 1;
    for (size_t i = open + 1; i < label.size(); ++i) {
        char c = label[i];
        if (c == '(' || c == '[') ++depth;
        else if ((c == ')' || c == ']') && depth > 0) --depth;
        else if ((c == ',' || c == ')') && depth == 0) {
            while (start < i && label[start] == ' ') ++start;
            if (i > start) spans.push_back({start, i});
            if (c == ')') break;
            start = i + 1;
        }
    }
    return spans;
}

}  // namespace

json foldingRanges(const Analysis& a) {
    json out = json::array();
    if (a.mainFile < 0) return out;
    const SourceFile& f = a.sources->file(a.mainFile);
    if (a.parsed) foldSymbols(f, a.symbols, out);
    foldComments(f, out);
    return out;
}

json workspaceSymbols(const std::vector<const Analysis*>& analyses, const std::string& query) {
    json out = json::array();
    for (const Analysis* a : analyses)
        if (a && a->parsed) flatten(a->symbols, "", query, a->sources->file(a->mainFile), out);
    return out;
}

json signatureHelp(const Analysis& a, const std::string& text, uint32_t offset) {
    // The innermost call whose parentheses are open at the cursor, and the argument it is in.
    size_t at = std::min<size_t>(offset, text.size());
    int depth = 0, argument = 0;
    size_t open = std::string::npos;
    for (size_t i = at; i-- > 0;) {
        char c = text[i];
        if (c == ')' || c == ']') ++depth;
        else if (c == '(' || c == '[') {
            if (depth == 0) {
                if (c == '(') open = i;
                break;
            }
            --depth;
        } else if (c == ',' && depth == 0) ++argument;
        else if ((c == ';' || c == '{' || c == '}') && depth == 0) break;
    }
    if (open == std::string::npos) return nullptr;
    size_t end = open;
    while (end > 0 && text[end - 1] == ' ') --end;
    size_t start = end;
    while (start > 0 && (std::isalnum(static_cast<unsigned char>(text[start - 1])) || text[start - 1] == '_')) --start;
    std::string name = text.substr(start, end - start);
    if (name.empty()) return nullptr;
    // The word before the name: `emit spark(` and `spawn rocket(` give an object's parameters.
    size_t wordEnd = start;
    while (wordEnd > 0 && std::isspace(static_cast<unsigned char>(text[wordEnd - 1]))) --wordEnd;
    size_t wordStart = wordEnd;
    while (wordStart > 0 && std::isalpha(static_cast<unsigned char>(text[wordStart - 1]))) --wordStart;
    std::string before = text.substr(wordStart, wordEnd - wordStart);
    std::string label, doc;
    if (before == "emit" || before == "spawn") {
        auto object = [&](const std::vector<Name>& names) {
            for (const Name& n : names)
                if (n.label == name && n.kind == CompletionKind::Class) label = n.detail, doc = n.documentation;
        };
        object(a.globals);
        for (const Scope& s : a.scopes)  // a nested object, named where the cursor is
            if (s.range.file == a.mainFile && s.range.begin <= offset && offset <= s.range.end) object(s.names);
    } else if (auto draw = core::fromName<core::DrawKind>(name, core::kDrawKindNames)) {
        label = drawCallSignature(*draw), doc = std::string(commandDoc(name));
    }
    for (const Name& n : a.globals)
        if (label.empty() && n.label == name && n.kind == CompletionKind::Function) label = n.detail, doc = n.documentation;
    if (label.empty())
        if (int b = findBuiltinFunction(name); b >= 0) label = std::string(builtinFunction(b).signature), doc = "built-in function";
    if (label.empty()) return nullptr;
    json parameters = json::array();
    for (auto [b, e] : parameterSpans(label)) parameters.push_back({{"label", {b, e}}});
    json signature = {{"label", label}, {"parameters", parameters}};
    if (!doc.empty()) signature["documentation"] = doc;
    int active = parameters.empty() ? 0 : std::min<int>(argument, static_cast<int>(parameters.size()) - 1);
    return {{"signatures", {signature}}, {"activeSignature", 0}, {"activeParameter", active}};
}

nlohmann::json semanticTokens(const Analysis& a, uint32_t begin, uint32_t stop) {
    std::vector<const Occurrence*> names;
    for (const Occurrence& o : a.occurrences)
        if (o.token.type != TokenType::None && o.range.file == a.mainFile && o.range.end > o.range.begin &&
            o.range.begin >= begin && o.range.begin < stop)
            names.push_back(&o);
    std::stable_sort(names.begin(), names.end(),
                     [](const Occurrence* x, const Occurrence* y) { return x->range.begin < y->range.begin; });
    // Five numbers a token, each place relative to the one before (the protocol's encoding).
    const SourceFile& f = a.sources->file(a.mainFile);
    nlohmann::json data = nlohmann::json::array();
    uint32_t line = 0, character = 0, end = 0;
    for (const Occurrence* o : names) {
        if (o->range.begin < end) continue;  // a name met twice (a tuple equation's, say)
        nlohmann::json from = position(f, o->range.begin), to = position(f, o->range.end);
        auto l = from["line"].get<uint32_t>(), c = from["character"].get<uint32_t>();
        if (to["line"].get<uint32_t>() != l) continue;
        data.push_back(l - line);
        data.push_back(l == line ? c - character : c);
        data.push_back(to["character"].get<uint32_t>() - c);
        data.push_back(static_cast<int>(o->token.type));
        data.push_back(o->token.modifiers);
        line = l, character = c, end = o->range.end;
    }
    return {{"data", data}};
}

nlohmann::json semanticTokensEdits(const nlohmann::json& before, const nlohmann::json& after) {
    // One edit: the numbers between the common start and the common end. An edit inside
    // one declaration leaves the numbers before it as they were, and those after it too
    // (each token's place is relative to the one before).
    size_t prefix = 0, suffix = 0;
    while (prefix < before.size() && prefix < after.size() && before[prefix] == after[prefix]) ++prefix;
    while (suffix < before.size() - prefix && suffix < after.size() - prefix &&
           before[before.size() - 1 - suffix] == after[after.size() - 1 - suffix])
        ++suffix;
    nlohmann::json edits = nlohmann::json::array();
    if (prefix == before.size() && prefix == after.size()) return edits;
    nlohmann::json data = nlohmann::json::array();
    for (size_t i = prefix; i < after.size() - suffix; ++i) data.push_back(after[i]);
    edits.push_back({{"start", prefix}, {"deleteCount", before.size() - suffix - prefix}, {"data", data}});
    return edits;
}

nlohmann::json semanticTokensLegend() {
    return {{"tokenTypes", kTokenTypes}, {"tokenModifiers", kTokenModifiers}};
}

}  // namespace psys::lsp
