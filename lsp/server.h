// `psysc lsp`: the language server. Documents the editor has open are kept as text; each is
// analysed when opened and again once edits have paused for the debounce interval, and
// its diagnostics are published then. The open documents are the truth: a file imported
// by another is read from the editor's text where it is open, saved or not, and an edit to
// it analyses its importers again. A request that edits (rename, quick fixes), references
// and pulled diagnostics analyse a changed document first, so they match its text; reads
// (hover, definition, symbols, tokens) do too where that is quick, and otherwise answer at
// once from the last analysis moved through the edits since (Server::readable).
//
// A debounced analysis runs on a thread of its own, one at a time, so the server goes on
// reading while it runs: edits, requests about the other documents, completion and
// signature help (from the last text that parsed), shutdown. An edit to the document being
// analysed cancels that analysis (it stops at its next phase and is never published).
//
// An edit's analysis parses only the top-level declarations it changed (the document's
// frontend/parse_cache.h). Where the compiler's passes took long on the document (their
// warnings: an unstable decay, an integral with no closed form), an edit's analysis leaves
// them out: it checks again only the declarations the edit can change, from the last
// analysis that parsed (lsp/incremental.h), and its diagnostics are published with the
// passes' last warnings carried through the edits; the passes run after, in a whole
// analysis of their own, published again.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lsp/analysis.h"
#include "lsp/params.h"
#include "lsp/recover.h"
#include "lsp/workspace.h"

namespace psys::lsp {

// A read waits for an analysis of the text it is asked about when the last one took
// less than this; otherwise it answers from the last analysis at once.
constexpr double kQuickAnalysisMs = 20;

// The longest debounce a client may ask for (initializationOptions.debounceMs): ten minutes.
constexpr uint64_t kMaxDebounceMs = 600000;

struct ServerOptions {
    std::chrono::milliseconds debounce{150};
    double quickAnalysisMs = kQuickAnalysisMs;
    std::string version = "0";
};

// A request's failure the client is told about (the protocol's error code and message).
struct RequestError {
    int code;
    std::string message;
};

class Server {
public:
    using Send = std::function<void(const nlohmann::json&)>;
    // A message as its JSON text: an answer too big to build as a tree (an outline of
    // 15,000 symbols) is written as text. Without one, such an answer is parsed back into
    // a tree and goes through `send`.
    using SendText = std::function<void(const std::string&)>;
    Server(ServerOptions options, Send send, SendText sendText = {})
        : options_(std::move(options)), send_(std::move(send)), sendText_(std::move(sendText)) {}
    ~Server() {
        if (pending_) pending_->cancelled->store(true);  // its future waits for it to stop
    }

    // One message from the client: answers and notifications go out through `send`.
    void handle(const nlohmann::json& message);
    // Publishes the analysis that has finished in the background, if any, and starts the
    // next of the documents whose debounce has run out.
    void idle();
    // An analysis is running in the background (a document's or the workspace index's),
    // or a document's passes are still to run.
    bool busy() const;
    // Waits for the background analysis and publishes it (if its text is still current).
    void settle();
    // How long until idle() has work (nullopt: none pending).
    std::optional<std::chrono::milliseconds> nextDeadline() const;
    // Set once `exit` arrives: the process's exit code (0 after `shutdown`, 1 without).
    std::optional<int> exitCode() const { return exitCode_; }

private:
    using Clock = std::chrono::steady_clock;
    struct Document {
        std::string uri, path, text;
        int64_t version = 0;
        bool dirty = false;
        Clock::time_point changedAt;
        std::shared_ptr<const Analysis> analysis, lastParsed;
        std::set<std::string> publishedTo;  // URIs this document's diagnostics went to
        uint64_t edits = 0;                 // counts changes: an analysis of an older text is stale
        std::shared_ptr<const Analysis> moved;  // `analysis` moved to the text of `movedAt` edits
        uint64_t movedAt = UINT64_MAX;
        std::shared_ptr<const EditMap> map;     // from `analysis`'s text to the text of `mapAt` edits
        uint64_t mapAt = UINT64_MAX;
        std::string tokensId;               // the last semantic tokens sent (for a delta from them)
        nlohmann::json tokens;
        // Its declarations as last parsed: an analysis parses only what the edits changed
        // (shared with the analysis running in the background).
        std::shared_ptr<ParseCache> parses = std::make_shared<ParseCache>();
        // The last analysis the compiler's passes ran in, and how long they took. Where
        // they are slow, an edit's analysis publishes the front end's diagnostics first
        // (with the passes' last warnings carried through the edits), and the passes run
        // after it, in an analysis of their own (`passesDue`).
        std::shared_ptr<const Analysis> passed;
        double passesMs = 0;
        bool passesDue = false;
        uint64_t sweptAt = UINT64_MAX;  // the edit count of the text the parse cache was last swept at
    };
    struct Pending {
        std::string uri;
        uint64_t edits;
        std::shared_ptr<std::atomic<bool>> cancelled;
        std::future<Analysis> result;
    };
    // Starts `doc`'s analysis in the background (the passes in it or not).
    void start(Document& doc, bool passes);

    nlohmann::json dispatch(const std::string& method, const Field& params, bool* found);
    // lsp/server_requests.cpp: the requests about documents: reads, then edits.
    nlohmann::json request(const std::string& method, const Field& params, bool* found);
    nlohmann::json editRequest(const std::string& method, const Field& params, bool* found);
    nlohmann::json initialize(const Field& params);
    void didOpen(const Field& params);
    void didChange(const Field& params);
    void didClose(const Field& params);
    Document& document(const Field& params);  // the open document a request names, analysed
    Document& openDocument(const Field& params);  // the same, as it is
    // What reads answer from: the analysis of the text as it is where it is current, or
    // will be soon (the last one took under kQuickAnalysis); else, at once, the last
    // analysis moved through the edits since (lsp/recover.h), which knows nothing of what
    // they changed until the new analysis is in.
    const Analysis& readable(const Field& params);
    // Whether reads about `doc` answer from its last analysis (moved through the edits
    // since) rather than wait for one of its text: that text is not analysed yet, and the
    // last analysis took longer than quickAnalysisMs.
    bool answersFromLast(const Document& doc) const;
    // Hover and definition where readable() would move the last analysis: the place asked
    // about mapped back into its text, the answer mapped forward (no copy of the index).
    // Nullopt where readable() is what answers.
    std::optional<nlohmann::json> throughEdits(const Field& params, bool definition);
    // The outline as JSON text (readable()'s, or the last analysis's symbols moved
    // through the edits where readable() would move the whole analysis).
    std::string outline(const Field& params);
    // From the text of `doc`'s analysis to its text now (made once per edit).
    const EditMap& editMap(Document& doc);
    // Every open document's analysis, and every other file's of the workspace index.
    std::vector<const Analysis*> analyses();
    nlohmann::json withUris(nlohmann::json answer) const;
    void analyse(Document& doc);
    // The open documents' texts but `doc`'s, for an analysis of `doc` to import.
    SourceOverrides openTexts(const Document* except) const;
    // `changed`'s text is not what the documents importing it last read: each is analysed
    // again (once edits pause), an analysis of theirs that is running thrown away.
    void touchImporters(const Document& changed);
    void install(Document& doc, Analysis fresh);
    void cancelPending(const std::string& uri);
    void publish(Document& doc);
    void notify(const std::string& method, nlohmann::json params);

    ServerOptions options_;
    Send send_;
    SendText sendText_;
    std::optional<std::string> textResult_;  // a request's answer written as JSON text (outline)
    std::map<std::string, Document> docs_;  // by URI
    std::optional<Pending> pending_;        // the analysis running in the background
    WorkspaceIndex index_;                  // the workspace folders' files
    bool initialized_ = false, shutdown_ = false;
    uint64_t tokenResults_ = 0;  // numbers the semantic tokens' result ids
    bool indexing_ = false;      // the workspace index is analysing in the background
    bool pulls_ = false;         // the client pulls diagnostics (it said so in initialize)
    std::optional<int> exitCode_;
};

// Serves the protocol on two file descriptors until `exit` or the end of input.
int serve(int in, int out, ServerOptions options);

}  // namespace psys::lsp
