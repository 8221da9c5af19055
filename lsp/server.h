// `psysc lsp`: the language server. Documents the editor has open are kept as text; each is
// analysed when opened and again once edits have paused for the debounce interval, and
// its diagnostics are published then. Requests about a document analyse it first if it
// has changed since, so an answer always matches the text it is asked about.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lsp/analysis.h"

namespace psys::lsp {

// The longest debounce a client may ask for (initializationOptions.debounceMs): ten minutes.
constexpr uint64_t kMaxDebounceMs = 600000;

struct ServerOptions {
    std::chrono::milliseconds debounce{150};
    std::string version = "0";
};

class Server {
public:
    using Send = std::function<void(const nlohmann::json&)>;
    Server(ServerOptions options, Send send) : options_(std::move(options)), send_(std::move(send)) {}

    // One message from the client: answers and notifications go out through `send`.
    void handle(const nlohmann::json& message);
    // Analyses the documents whose debounce has run out, and publishes their diagnostics.
    void idle();
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
    };

    nlohmann::json dispatch(const std::string& method, const nlohmann::json& params, bool* found);
    nlohmann::json initialize(const nlohmann::json& params);
    void didOpen(const nlohmann::json& params);
    void didChange(const nlohmann::json& params);
    void didClose(const nlohmann::json& params);
    Document& document(const nlohmann::json& params);  // the open document a request names, analysed
    std::vector<const Analysis*> analyses();  // every open document's, analysed
    nlohmann::json withUris(nlohmann::json answer) const;
    void analyse(Document& doc);
    void publish(Document& doc);
    void notify(const std::string& method, nlohmann::json params);

    ServerOptions options_;
    Send send_;
    std::map<std::string, Document> docs_;  // by URI
    bool initialized_ = false, shutdown_ = false;
    std::optional<int> exitCode_;
};

// Serves the protocol on two file descriptors until `exit` or the end of input.
int serve(int in, int out, ServerOptions options);

}  // namespace psys::lsp
