// The requests about documents and the workspace. Reads (hover, definition, symbols,
// tokens, …) answer from Server::readable: the analysis of the text as it is, or, while
// that would take long, the last one moved through the edits since. Completion and
// signature help read the last text that parsed with the cursor in the text as it is now.
// What edits the text (rename, quick fixes), references and pulled diagnostics wait for
// the analysis of the text they are asked about.
#include <algorithm>

#include "lsp/features.h"
#include "lsp/positions.h"
#include "lsp/recover.h"
#include "lsp/references.h"
#include "lsp/server.h"
#include "lsp/transport.h"

namespace psys::lsp {

using nlohmann::json;

namespace {

std::string query(const Field& params) {
    auto q = params.get("query");
    return q ? q->string() : std::string();
}

template <typename T>
T orRefuse(std::variant<T, std::string> answer) {
    if (auto* why = std::get_if<std::string>(&answer)) throw RequestError{error::kRequestFailed, *why};
    return std::get<T>(std::move(answer));
}

}  // namespace

json Server::request(const std::string& method, const Field& params, bool* found) {
    // Reads answer from readable(): never behind an analysis that takes long.
    auto main = [](const Analysis& a) -> const SourceFile& { return a.sources->file(a.mainFile); };
    auto offset = [&](const Analysis& a) { return offsetOf(main(a), params["position"]); };
    if (method == "textDocument/hover") {
        if (auto answer = throughEdits(params, false)) return *answer;
        const Analysis& a = readable(params);
        return hover(a, offset(a));
    }
    // A name's declaration is where it is defined: the language has no declarations apart.
    if (method == "textDocument/definition" || method == "textDocument/declaration") {
        if (auto answer = throughEdits(params, true)) return *answer;
        const Analysis& a = readable(params);
        json found = definition(a, offset(a));
        return found.is_null() ? found : withUris(json::array({found}))[0];  // (the editor's spelling of its URIs)
    }
    if (method == "textDocument/documentSymbol") {
        textResult_ = outline(params);
        return nullptr;
    }
    if (method == "textDocument/semanticTokens/full" || method == "textDocument/semanticTokens/full/delta") {
        json tokens = semanticTokens(readable(params));
        Document& doc = openDocument(params);
        auto previous = params.get("previousResultId");
        bool delta = previous && previous->string() == doc.tokensId && !doc.tokensId.empty();
        json answer = {{"resultId", std::to_string(++tokenResults_)}};
        if (delta) answer["edits"] = semanticTokensEdits(doc.tokens["data"], tokens["data"]);
        else answer["data"] = tokens["data"];
        doc.tokensId = answer["resultId"];
        doc.tokens = std::move(tokens);
        return answer;
    }
    if (method == "textDocument/semanticTokens/range") {
        const Analysis& a = readable(params);
        return semanticTokens(a, offsetOf(main(a), params["range"]["start"]), offsetOf(main(a), params["range"]["end"]));
    }
    if (method == "textDocument/foldingRange") return foldingRanges(readable(params));
    if (method == "textDocument/documentLink") return withUris(documentLinks(readable(params)));
    if (method == "textDocument/selectionRange") {
        const Analysis& a = readable(params);
        Field positions = params["positions"];
        json answer = json::array();
        for (size_t i = 0; i < positions.array().size(); ++i)
            answer.push_back(selectionRange(a, offsetOf(main(a), Field(positions.json()[i], "positions[" + std::to_string(i) + "]"))));
        return answer;
    }
    if (method == "textDocument/inlayHint") {
        const Analysis& a = readable(params);
        return inlayHints(a, offsetOf(main(a), params["range"]["start"]), offsetOf(main(a), params["range"]["end"]));
    }
    if (method == "textDocument/documentHighlight") {
        const Analysis& a = readable(params);
        return highlights(a, offset(a));
    }
    // The diagnostics the editor pulls are the text's own: they wait for its analysis.
    if (method == "textDocument/diagnostic") return documentDiagnostics(*document(params).analysis);
    if (method == "workspace/symbol") return withUris(workspaceSymbols(analyses(), query(params)));
    if (method == "completionItem/resolve") return resolveCompletion(params.object());
    // Completion and signature help read names from the last text that parsed and the
    // cursor in the text as it is now: they need not wait for an analysis.
    auto typing = [&](auto answer) -> json {
        Document* doc = &openDocument(params);
        if (!doc->lastParsed && !doc->analysis) doc = &document(params);
        const Analysis& names = doc->lastParsed ? *doc->lastParsed : *doc->analysis;
        return answer(names, doc->text, offsetOf(SourceFile(doc->path, doc->text), params["position"]));
    };
    if (method == "textDocument/signatureHelp")
        return typing([](const Analysis& a, const std::string& text, uint32_t at) { return signatureHelp(a, text, at); });
    if (method == "textDocument/completion")
        return typing([](const Analysis& a, const std::string& text, uint32_t at) { return completion(a, text, at); });
    if (method == "textDocument/references") {
        Document& doc = document(params);
        auto d = declarationAt(*doc.analysis, offsetOf(main(*doc.analysis), params["position"]));
        if (!d) return nullptr;
        auto context = params.get("context");
        auto include = context ? context->get("includeDeclaration") : std::nullopt;
        bool withDeclaration = include ? include->boolean() : true;
        return withUris(references(analyses(), *d, withDeclaration));
    }
    return editRequest(method, params, found);
}

const EditMap& Server::editMap(Document& doc) {
    if (doc.mapAt != doc.edits) {
        const Analysis& a = *doc.analysis;
        doc.map = std::make_shared<const EditMap>(a.sources->file(a.mainFile).text(), doc.text);
        doc.mapAt = doc.edits;
    }
    return *doc.map;
}

std::string Server::outline(const Field& params) {
    Document& doc = openDocument(params);
    if (!answersFromLast(doc) || !doc.analysis->parsed || doc.movedAt == doc.edits) return documentSymbols(readable(params));
    SourceFile now(doc.path, doc.text);
    return documentSymbols(now, movedSymbols(*doc.analysis, editMap(doc)));
}

std::optional<json> Server::throughEdits(const Field& params, bool wantDefinition) {
    Document& doc = openDocument(params);
    if (!answersFromLast(doc) || !doc.analysis->parsed || doc.movedAt == doc.edits) return std::nullopt;
    // The place asked about, in the text the last analysis read; what is there, moved back
    // into the text as it is (nothing where the edits since touched it).
    const Analysis& a = *doc.analysis;
    const EditMap& map = editMap(doc);
    SourceFile now(doc.path, doc.text);
    uint32_t cursor = offsetOf(now, params["position"]);
    auto older = map.toOlder(cursor);
    const Occurrence* o = older ? a.at(a.mainFile, *older) : nullptr;
    auto moved = [&](SourceRange r) -> std::optional<SourceRange> {
        if (r.file != a.mainFile) return r;
        if (map.touches(r.begin, r.end)) return std::nullopt;  // edited inside
        auto b = map.toCurrent(r.begin, true), e = map.toCurrent(r.end);
        if (!b || !e || *e < *b) return std::nullopt;
        return SourceRange{r.file, *b, *e};
    };
    auto at = o ? moved(o->range) : std::nullopt;
    if (!at || cursor < at->begin || cursor > at->end) return json(nullptr);  // (typed onto its end: another name)
    auto where = [&](SourceRange r) -> json {
        const SourceFile& f = r.file == a.mainFile ? now : a.sources->file(r.file);
        return {{"uri", uriFromPath(f.path())}, {"range", range(f, r.begin, r.end)}};
    };
    if (wantDefinition) {
        auto d = o->definition && o->definition->valid() ? moved(*o->definition) : std::nullopt;
        return d ? withUris(json::array({where(*d)}))[0] : json(nullptr);
    }
    if (!o->hover || o->hover->empty()) return json(nullptr);
    return json{{"contents", {{"kind", "markdown"}, {"value", *o->hover}}}, {"range", range(now, at->begin, at->end)}};
}

json Server::editRequest(const std::string& method, const Field& params, bool* found) {
    auto mainFile = [](Document& doc) -> const SourceFile& { return doc.analysis->sources->file(doc.analysis->mainFile); };
    auto offset = [&](Document& doc) { return offsetOf(mainFile(doc), params["position"]); };
    if (method == "textDocument/prepareRename") {
        Document& doc = document(params);
        return orRefuse(prepareRename(*doc.analysis, offset(doc)));
    }
    if (method == "textDocument/rename") {
        Document& doc = document(params);
        return withUris(orRefuse(rename(analyses(), *doc.analysis, offset(doc), params["newName"].string())));
    }
    if (method == "textDocument/codeAction") {
        Document& doc = document(params);
        const SourceFile& f = mainFile(doc);
        uint32_t begin = offsetOf(f, params["range"]["start"]), end = offsetOf(f, params["range"]["end"]);
        // The diagnostics the client shows where the cursor is (its whole line, for some)
        // count too, though the cursor is not on them.
        auto context = params.get("context");
        auto shown = context ? context->get("diagnostics") : std::nullopt;
        for (size_t i = 0; shown && i < shown->array().size(); ++i) {
            Field d(shown->json()[i], shown->path() + "[" + std::to_string(i) + "]");
            begin = std::min(begin, offsetOf(f, d["range"]["start"]));
            end = std::max(end, offsetOf(f, d["range"]["end"]));
        }
        json actions = codeActions(*doc.analysis, begin, end);
        for (json& action : actions) action["edit"] = withUris(action["edit"]);
        return actions;
    }
    // Formatting reads the text as it is now: it needs no analysis, but where the one it
    // has is of this text and it parsed, the text is not parsed again.
    auto parses = [this](const Document& doc) {
        bool running = pending_ && pending_->uri == doc.uri;
        return !doc.dirty && !running && doc.analysis && doc.analysis->parsed && !doc.analysis->recovered;
    };
    // (Where the analysis is current, the text's tokens are its parse's.)
    auto tokens = [&](const Document& doc) { return parses(doc) ? doc.parses->tokens(doc.text) : std::nullopt; };
    if (method == "textDocument/formatting") {
        Document& doc = openDocument(params);
        auto lexed = tokens(doc);
        return orRefuse(formatting(doc.path, doc.text, parses(doc), lexed ? &*lexed : nullptr));
    }
    if (method == "textDocument/rangeFormatting") {
        Document& doc = openDocument(params);
        SourceFile f(doc.path, doc.text);
        auto lexed = tokens(doc);
        return orRefuse(rangeFormatting(doc.path, doc.text, offsetOf(f, params["range"]["start"]),
                                        offsetOf(f, params["range"]["end"]), parses(doc), lexed ? &*lexed : nullptr));
    }
    *found = false;
    return nullptr;
}

}  // namespace psys::lsp
