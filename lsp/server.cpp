#include "lsp/server.h"

#include <algorithm>
#include <csignal>
#include <utility>
#include <variant>

#include "lsp/features.h"
#include "lsp/positions.h"
#include "lsp/recover.h"
#include "lsp/references.h"
#include "lsp/transport.h"

namespace psys::lsp {

using nlohmann::json;

namespace {

bool isNotification(const json& m) { return !m.contains("id"); }

// The folders of the workspace, as paths: `workspaceFolders`, else `rootUri`, else `rootPath`.
std::vector<std::string> workspaceFolders(const Field& params) {
    std::vector<std::string> out;
    if (auto folders = params.get("workspaceFolders")) {
        for (size_t i = 0; i < folders->array().size(); ++i)
            out.push_back(pathFromUri(Field(folders->json()[i], "workspaceFolders[" + std::to_string(i) + "]")["uri"].string()));
    } else if (auto root = params.get("rootUri")) {
        out.push_back(pathFromUri(root->string()));
    } else if (auto path = params.get("rootPath")) {
        out.push_back(path->string());
    }
    return out;
}

// A document's version: a whole number where given.
int64_t version(const Field& textDocument, int64_t otherwise) {
    auto v = textDocument.get("version");
    if (!v) return otherwise;
    if (!v->json().is_number_integer()) v->refuse("a whole number");
    return v->json().get<int64_t>();
}

}  // namespace

void Server::notify(const std::string& method, json params) {
    send_({{"jsonrpc", "2.0"}, {"method", method}, {"params", std::move(params)}});
}

void Server::handle(const json& m) {
    if (!m.is_object() || !m.contains("jsonrpc") || m["jsonrpc"] != "2.0" ||
        (m.contains("method") && !m["method"].is_string()) ||
        (m.contains("id") && !m["id"].is_number_integer() && !m["id"].is_string() && !m["id"].is_null())) {
        json id = m.is_object() && m.contains("id") && (m["id"].is_number_integer() || m["id"].is_string()) ? m["id"] : json();
        send_(errorResponse(id, error::kInvalidRequest, "not a JSON-RPC 2.0 request or notification"));
        return;
    }
    if (!m.contains("method")) return;  // a response to something the server never asks
    std::string method = m["method"];
    json params = m.contains("params") ? m["params"] : json::object();
    bool notification = isNotification(m);
    json id = notification ? json() : m["id"];
    if (method == "exit") {
        exitCode_ = shutdown_ ? 0 : 1;
        return;
    }
    try {
        if (!initialized_ && method != "initialize")
            throw RequestError{error::kServerNotInitialized, "the server has not been initialised"};
        if (shutdown_) throw RequestError{error::kInvalidRequest, "the server is shutting down: only `exit` is accepted"};
        bool found = false;
        textResult_.reset();
        json result = dispatch(method, Field(params, ""), &found);
        std::optional<std::string> text = std::exchange(textResult_, std::nullopt);
        if (!found) {
            if (notification) return;  // notifications the server does not know are ignored, as the protocol says
            throw RequestError{error::kMethodNotFound, "no method `" + method + "`"};
        }
        if (!notification && text) {
            std::string answer = R"({"id":)" + id.dump() + R"(,"jsonrpc":"2.0","result":)" + *text + "}";
            if (sendText_) sendText_(answer);
            else send_(json::parse(answer));
        } else if (!notification) {
            json answer = {{"jsonrpc", "2.0"}, {"id", id}};
            answer["result"] = std::move(result);
            send_(answer);
        }
    } catch (const RequestError& e) {
        if (!notification) send_(errorResponse(id, e.code, e.message));
    } catch (const InvalidParams& e) {
        if (!notification) send_(errorResponse(id, error::kInvalidParams, std::string("invalid params: ") + e.what()));
    } catch (const std::exception& e) {
        if (!notification) send_(errorResponse(id, error::kInternalError, e.what()));
    }
}

json Server::dispatch(const std::string& method, const Field& params, bool* found) {
    *found = true;
    if (method == "initialize") return initialize(params);
    if (method == "initialized") return nullptr;
    if (method == "shutdown") {
        shutdown_ = true;
        return nullptr;
    }
    if (method == "textDocument/didOpen") {
        didOpen(params);
        return nullptr;
    }
    if (method == "textDocument/didChange") {
        didChange(params);
        return nullptr;
    }
    if (method == "textDocument/didClose") {
        didClose(params);
        return nullptr;
    }
    if (method == "textDocument/didSave" || method == "workspace/didChangeWatchedFiles") {
        // A saved file, or one changed on disk, may be imported by the open ones: they
        // are analysed again; the index reads it again.
        for (auto& [uri, doc] : docs_) doc.dirty = true, doc.changedAt = Clock::now() - options_.debounce;
        if (method == "textDocument/didSave") index_.changed(pathFromUri(params["textDocument"]["uri"].string()));
        auto changes = params.get("changes");
        for (size_t i = 0; changes && i < changes->array().size(); ++i) {
            Field change(changes->json()[i], "changes[" + std::to_string(i) + "]");
            std::string path = pathFromUri(change["uri"].string());
            if (!path.ends_with(".psys")) continue;
            if (change["type"].json() == 3) index_.removed(path);  // FileChangeType: 1 created, 2 changed, 3 deleted
            else index_.changed(path);
        }
        return nullptr;
    }
    if (method.starts_with("textDocument/") || method.starts_with("workspace/") || method.starts_with("completionItem/"))
        return request(method, params, found);
    *found = false;
    return nullptr;
}

json Server::initialize(const Field& field) {
    const json& params = field.object();
    if (initialized_) throw RequestError{error::kInvalidRequest, "the server is already initialised"};
    // The options are checked first: an initialize that fails leaves the server as it was.
    if (params.contains("initializationOptions") && params["initializationOptions"].is_object()) {
        const json& o = params["initializationOptions"];
        if (o.contains("debounceMs")) {
            const json& d = o["debounceMs"];
            bool whole = d.is_number_unsigned() || (d.is_number_integer() && d.get<int64_t>() >= 0);
            if (!whole || d.get<uint64_t>() > kMaxDebounceMs)
                throw RequestError{error::kInvalidParams,
                                   "initializationOptions.debounceMs is a whole number of milliseconds from 0 to " +
                                       std::to_string(kMaxDebounceMs) + ", not " + d.dump()};
            options_.debounce = std::chrono::milliseconds(d.get<int64_t>());
        }
    }
    std::vector<std::string> folders = workspaceFolders(field);
    // A client that pulls diagnostics (textDocument/diagnostic) gets each document's own
    // that way only: pushed too, it would list each twice.
    if (auto capabilities = field.get("capabilities"))
        if (auto text = capabilities->get("textDocument")) pulls_ = text->get("diagnostic").has_value();
    initialized_ = true;
    index_.setFolders(folders);
    json answer = {{"capabilities",
             {{"textDocumentSync", {{"openClose", true}, {"change", 2}, {"save", true}}},
              {"hoverProvider", true},
              {"definitionProvider", true},
              {"documentSymbolProvider", true},
              {"referencesProvider", true},
              {"documentHighlightProvider", true},
              {"renameProvider", {{"prepareProvider", true}}},
              {"declarationProvider", true},
              {"documentLinkProvider", {{"resolveProvider", false}}},
              {"selectionRangeProvider", true},
              {"documentRangeFormattingProvider", true},
              {"inlayHintProvider", true},
              {"codeActionProvider", {{"codeActionKinds", {"quickfix"}}}},
              {"documentFormattingProvider", true},
              {"semanticTokensProvider", {{"legend", semanticTokensLegend()}, {"full", {{"delta", true}}}, {"range", true}}},
              {"foldingRangeProvider", true},
              {"workspaceSymbolProvider", true},
              {"signatureHelpProvider", {{"triggerCharacters", {"(", ","}}}},
              {"completionProvider", {{"triggerCharacters", {".", "@"}}, {"resolveProvider", true}}}}},
            {"serverInfo", {{"name", "psysc"}, {"version", options_.version}}}};
    if (pulls_)
        answer["capabilities"]["diagnosticProvider"] = {{"interFileDependencies", true}, {"workspaceDiagnostics", false}};
    return answer;
}

void Server::didOpen(const Field& params) {
    Field td = params["textDocument"];
    Document doc;
    doc.uri = td["uri"].string();
    doc.path = pathFromUri(doc.uri);
    doc.text = td["text"].string();
    doc.version = version(td, 0);
    cancelPending(doc.uri);
    auto old = docs_.find(doc.uri);
    doc.edits = old == docs_.end() ? 0 : old->second.edits + 1;
    auto [it, _] = docs_.insert_or_assign(doc.uri, std::move(doc));
    analyse(it->second);
    touchImporters(it->second);
}

void Server::didChange(const Field& params) {
    std::string uri = params["textDocument"]["uri"].string();
    auto it = docs_.find(uri);
    if (it == docs_.end()) throw RequestError{error::kInvalidParams, uri + " is not open"};
    Document& doc = it->second;
    // Every change is read before any is applied: a bad one leaves the text as it was.
    Field changes = params["contentChanges"];
    std::string text = doc.text;
    for (size_t i = 0; i < changes.array().size(); ++i) {
        Field change(changes.json()[i], "contentChanges[" + std::to_string(i) + "]");
        auto range = change.get("range");
        if (!range) {
            text = change["text"].string();
            continue;
        }
        // An incremental change: positions are in the text as it stands before this change.
        SourceFile current(doc.path, text);
        uint32_t begin = offsetOf(current, (*range)["start"]);
        uint32_t end = std::max(begin, offsetOf(current, (*range)["end"]));
        text.replace(begin, end - begin, change["text"].string());
    }
    doc.text = std::move(text);
    doc.version = version(params["textDocument"], doc.version);
    doc.dirty = true;
    doc.changedAt = Clock::now();
    ++doc.edits;
    cancelPending(uri);
    touchImporters(doc);
}

void Server::touchImporters(const Document& changed) {
    std::string key = sourceKey(changed.path);
    index_.importChanged(key);
    for (auto& [uri, doc] : docs_) {
        if (&doc == &changed) continue;
        bool imports = (doc.analysis && doc.analysis->imported.count(key)) ||
                       (doc.lastParsed && doc.lastParsed->imported.count(key));
        if (!imports) continue;
        doc.dirty = true;
        doc.changedAt = Clock::now();
        ++doc.edits;  // (what it read is not the text now)
        cancelPending(uri);
    }
}

SourceOverrides Server::openTexts(const Document* except) const {
    SourceOverrides open;
    for (const auto& [uri, other] : docs_)
        if (&other != except) open[sourceKey(other.path)] = other.text;
    return open;
}

void Server::cancelPending(const std::string& uri) {
    if (pending_ && pending_->uri == uri) pending_->cancelled->store(true);
}

void Server::didClose(const Field& params) {
    auto it = docs_.find(params["textDocument"]["uri"].string());
    if (it == docs_.end()) return;
    cancelPending(it->first);
    for (const std::string& uri : it->second.publishedTo)
        notify("textDocument/publishDiagnostics", {{"uri", uri}, {"diagnostics", json::array()}});
    Document closed = std::move(it->second);
    docs_.erase(it);
    touchImporters(closed);  // (they read it from disk now)
}

std::vector<const Analysis*> Server::analyses() {
    std::vector<const Analysis*> out;
    settle();
    std::set<std::string> open;
    for (auto& [uri, doc] : docs_) {
        if (doc.dirty) analyse(doc);
        out.push_back(doc.analysis.get());
        open.insert(sourceKey(doc.path));
    }
    std::vector<const Analysis*> indexed = index_.all(openTexts(nullptr), open);
    out.insert(out.end(), indexed.begin(), indexed.end());
    return out;
}

// An answer's URIs as the editor spells its open documents' (a path's own URI may differ).
json Server::withUris(json answer) const {
    std::map<std::string, std::string> spelling;
    for (const auto& [uri, doc] : docs_) spelling[uriFromPath(doc.path)] = uri;
    auto respell = [&](const std::string& uri) {
        auto it = spelling.find(uri);
        return it == spelling.end() ? uri : it->second;
    };
    if (answer.is_array()) {
        for (json& entry : answer) {  // locations, symbols with one, or links
            if (entry.contains("target")) {
                entry["target"] = respell(entry["target"]);
                continue;
            }
            json& location = entry.contains("location") ? entry["location"] : entry;
            location["uri"] = respell(location["uri"]);
        }
    } else if (answer.is_object() && answer.contains("changes")) {
        json changes = json::object();
        for (auto& [uri, edits] : answer["changes"].items()) changes[respell(uri)] = edits;
        answer["changes"] = changes;
    }
    return answer;
}

Server::Document& Server::openDocument(const Field& params) {
    std::string uri = params["textDocument"]["uri"].string();
    auto it = docs_.find(uri);
    if (it == docs_.end()) throw RequestError{error::kInvalidParams, uri + " is not open"};
    return it->second;
}

Server::Document& Server::document(const Field& params) {
    std::string uri = params["textDocument"]["uri"].string();
    auto it = docs_.find(uri);
    if (it == docs_.end()) throw RequestError{error::kInvalidParams, uri + " is not open"};
    if (pending_ && pending_->uri == uri) settle();
    if (it->second.dirty) {
        settle();  // one analysis at a time
        analyse(it->second);
    }
    return it->second;
}

bool Server::answersFromLast(const Document& doc) const {
    bool running = pending_ && pending_->uri == doc.uri;
    return doc.analysis && (doc.dirty || running) && doc.analysis->milliseconds >= options_.quickAnalysisMs;
}

const Analysis& Server::readable(const Field& params) {
    Document& doc = openDocument(params);
    if (!answersFromLast(doc)) return *document(params).analysis;
    if (doc.movedAt != doc.edits) {
        doc.moved = std::make_shared<const Analysis>(recover(*doc.analysis, *doc.analysis, doc.text, true));
        doc.movedAt = doc.edits;
    }
    return *doc.moved;
}

void Server::analyse(Document& doc) {
    SourceOverrides open = openTexts(&doc);
    // (Without the passes where they are slow, as in the background: a read that waits
    // for an analysis waits no longer than the last one took.)
    bool passes = doc.passesMs <= options_.quickAnalysisMs;
    install(doc, analyze(doc.path, doc.text, {.open = &open, .salvage = !doc.lastParsed, .passes = passes,
                                              .cache = doc.parses.get(), .previous = doc.lastParsed.get()}));
}

void Server::install(Document& doc, Analysis analysis) {
    bool clean = analysis.parsed && !analysis.recovered && analysis.passDiagnostics == analysis.diagnostics.size() &&
                 std::none_of(analysis.diagnostics.begin(), analysis.diagnostics.end(),
                              [](const Diagnostic& d) { return d.severity == Severity::Error; });
    if (analysis.passesRan) {
        doc.passesMs = analysis.passesMs;
        doc.passesDue = false;
    } else {
        // The passes run on a clean program only: due where the front end is clean, and
        // not (whatever was due before) where it is not.
        if (clean && doc.passed) carryPasses(*doc.passed, analysis);
        doc.passesDue = clean;
    }
    auto fresh = std::make_shared<const Analysis>(std::move(analysis));
    // The analysis replaced is freed after the diagnostics are out (100,000 occurrences
    // take a while to free).
    std::shared_ptr<const Analysis> replaced = doc.analysis;
    if (fresh->passesRan) doc.passed = fresh;
    doc.moved.reset(), doc.map.reset();  // (of the analysis this one replaces)
    doc.movedAt = doc.mapAt = UINT64_MAX;
    if (fresh->parsed && !fresh->recovered) doc.lastParsed = fresh;
    // A syntax error: hover, definition and symbols answer from the last text that parsed,
    // everywhere the edits since have not touched; with none, from the text's declarations
    // that parse (analyze's salvage).
    if (!fresh->parsed && doc.lastParsed && doc.lastParsed->mainFile >= 0)
        doc.analysis = std::make_shared<const Analysis>(recover(*doc.lastParsed, *fresh, doc.text));
    else
        doc.analysis = fresh;
    doc.dirty = false;
    if (doc.sweptAt != doc.edits) {  // (once a text: its passes' analysis comes after its first)
        doc.parses->sweep();            // what neither this text nor the one before used
        doc.sweptAt = doc.edits;
    }
    publish(doc);
    replaced.reset();
}

void Server::publish(Document& doc) {
    std::map<std::string, json> byUri = diagnosticsByUri(*doc.analysis);
    std::string mainUri = uriFromPath(doc.path);
    if (mainUri != doc.uri) {  // the editor's spelling of the document's URI is the one it knows
        byUri[doc.uri] = std::move(byUri[mainUri]);
        byUri.erase(mainUri);
    }
    for (const std::string& uri : doc.publishedTo)
        if (!byUri.count(uri)) byUri[uri] = json::array();
    doc.publishedTo.clear();
    for (auto& [uri, diagnostics] : byUri) {
        if (pulls_ && uri == doc.uri) continue;  // (the client pulls them)
        json params = {{"uri", uri}, {"diagnostics", diagnostics}};
        if (uri == doc.uri) params["version"] = doc.version;
        if (!diagnostics.empty() || uri == doc.uri) doc.publishedTo.insert(uri);
        notify("textDocument/publishDiagnostics", std::move(params));
    }
}

void Server::settle() {
    if (!pending_) return;
    Pending done = std::move(*pending_);
    pending_.reset();
    Analysis analysis = done.result.get();
    auto it = docs_.find(done.uri);
    // Published only if the text it analysed is still the document's.
    if (it != docs_.end() && it->second.edits == done.edits && !done.cancelled->load()) install(it->second, std::move(analysis));
}

void Server::idle() {
    if (pending_ && pending_->result.wait_for(std::chrono::seconds(0)) == std::future_status::ready) settle();
    indexing_ = index_.step([this] { return openTexts(nullptr); });
    if (pending_) return;
    auto now = Clock::now();
    for (auto& [uri, doc] : docs_) {
        if (!doc.dirty || now - doc.changedAt < options_.debounce) continue;
        return start(doc, doc.passesMs <= options_.quickAnalysisMs);
    }
    // Once every edit is analysed, the passes the slow ones were left out of.
    for (auto& [uri, doc] : docs_)
        if (doc.passesDue && !doc.dirty) return start(doc, true);
}

void Server::start(Document& doc, bool passes) {
    auto cancelled = std::make_shared<std::atomic<bool>>(false);
    pending_ = Pending{doc.uri, doc.edits, cancelled,
                       std::async(std::launch::async,
                                  [path = doc.path, text = doc.text, open = openTexts(&doc), cancelled,
                                   salvage = !doc.lastParsed, parses = doc.parses, passes, previous = doc.lastParsed] {
                                      return analyze(path, text, {.cancelled = cancelled.get(), .open = &open,
                                                                  .salvage = salvage, .passes = passes,
                                                                  .cache = parses.get(), .previous = previous.get()});
                                  })};
}

bool Server::busy() const {
    return pending_.has_value() || indexing_ ||
           std::any_of(docs_.begin(), docs_.end(), [](const auto& d) { return d.second.passesDue && !d.second.dirty; });
}

std::optional<std::chrono::milliseconds> Server::nextDeadline() const {
    // While an analysis runs in the background, the loop looks in on it every few milliseconds.
    if (pending_) return std::chrono::milliseconds(2);
    if (indexing_) return std::chrono::milliseconds(10);
    std::optional<std::chrono::milliseconds> next;
    auto now = Clock::now();
    for (const auto& [uri, doc] : docs_) {
        if (doc.passesDue && !doc.dirty) return std::chrono::milliseconds(0);
        if (!doc.dirty) continue;
        auto left = std::chrono::duration_cast<std::chrono::milliseconds>(doc.changedAt + options_.debounce - now);
        left = std::max(left, std::chrono::milliseconds(0));
        if (!next || left < *next) next = left;
    }
    return next;
}

int serve(int in, int out, ServerOptions options) {
    std::signal(SIGPIPE, SIG_IGN);  // a client that goes away is an end of input, not a signal
    Transport transport(in, out);
    Server server(std::move(options), [&transport](const json& m) { transport.write(m); },
                  [&transport](const std::string& text) { transport.writeText(text); });
    for (;;) {
        Incoming next = transport.read(server.nextDeadline());
        switch (next.kind) {
            case Incoming::Kind::Message: server.handle(next.json); break;
            case Incoming::Kind::Malformed: transport.write(errorResponse(nullptr, error::kParseError, next.problem)); break;
            case Incoming::Kind::Timeout: break;
            case Incoming::Kind::End: return 1;  // the client went away without `exit`
        }
        if (server.exitCode()) return *server.exitCode();
        server.idle();
    }
}

}  // namespace psys::lsp
