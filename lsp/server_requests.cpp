// The requests about documents and the workspace: each reads the analysis of the text it
// is asked about (Server::document analyses a changed text first), or, for completion and
// signature help, the last text that parsed with the cursor in the text as it is now.
#include <algorithm>

#include "lsp/features.h"
#include "lsp/positions.h"
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
    auto mainFile = [](Document& doc) -> const SourceFile& { return doc.analysis->sources->file(doc.analysis->mainFile); };
    auto offset = [&](Document& doc) { return offsetOf(mainFile(doc), params["position"]); };
    if (method == "textDocument/hover") {
        Document& doc = document(params);
        return hover(*doc.analysis, offset(doc));
    }
    // A name's declaration is where it is defined: the language has no declarations apart.
    if (method == "textDocument/definition" || method == "textDocument/declaration") {
        Document& doc = document(params);
        return definition(*doc.analysis, offset(doc));
    }
    if (method == "textDocument/documentSymbol") return documentSymbols(*document(params).analysis);
    if (method == "textDocument/semanticTokens/full" || method == "textDocument/semanticTokens/full/delta") {
        Document& doc = document(params);
        json tokens = semanticTokens(*doc.analysis);
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
        Document& doc = document(params);
        return semanticTokens(*doc.analysis, offsetOf(mainFile(doc), params["range"]["start"]),
                              offsetOf(mainFile(doc), params["range"]["end"]));
    }
    if (method == "textDocument/foldingRange") return foldingRanges(*document(params).analysis);
    if (method == "textDocument/documentLink") return withUris(documentLinks(*document(params).analysis));
    if (method == "textDocument/selectionRange") {
        Document& doc = document(params);
        Field positions = params["positions"];
        json answer = json::array();
        for (size_t i = 0; i < positions.array().size(); ++i)
            answer.push_back(selectionRange(
                *doc.analysis, offsetOf(mainFile(doc), Field(positions.json()[i], "positions[" + std::to_string(i) + "]"))));
        return answer;
    }
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
    if (method == "textDocument/inlayHint") {
        Document& doc = document(params);
        return inlayHints(*doc.analysis, offsetOf(mainFile(doc), params["range"]["start"]),
                          offsetOf(mainFile(doc), params["range"]["end"]));
    }
    if (method == "textDocument/references") {
        Document& doc = document(params);
        auto d = declarationAt(*doc.analysis, offset(doc));
        if (!d) return nullptr;
        auto context = params.get("context");
        auto include = context ? context->get("includeDeclaration") : std::nullopt;
        bool withDeclaration = include ? include->boolean() : true;
        return withUris(references(analyses(), *d, withDeclaration));
    }
    if (method == "textDocument/documentHighlight") {
        Document& doc = document(params);
        return highlights(*doc.analysis, offset(doc));
    }
    return editRequest(method, params, found);
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
    // Formatting reads the text as it is now: it needs no analysis.
    if (method == "textDocument/formatting") {
        Document& doc = openDocument(params);
        return orRefuse(formatting(doc.path, doc.text));
    }
    if (method == "textDocument/rangeFormatting") {
        Document& doc = openDocument(params);
        SourceFile f(doc.path, doc.text);
        return orRefuse(rangeFormatting(doc.path, doc.text, offsetOf(f, params["range"]["start"]),
                                        offsetOf(f, params["range"]["end"])));
    }
    *found = false;
    return nullptr;
}

}  // namespace psys::lsp
