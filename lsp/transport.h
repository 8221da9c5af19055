// JSON-RPC 2.0 messages framed as the Language Server Protocol frames them: a header
// (`Content-Length: N`, a blank line) and N bytes of JSON. Reads wait with a time limit,
// so the server can run debounced work between messages without a second thread.
#pragma once

#include <chrono>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

namespace psys::lsp {

// The protocol's error codes.
namespace error {
constexpr int kParseError = -32700;
constexpr int kInvalidRequest = -32600;
constexpr int kMethodNotFound = -32601;
constexpr int kInvalidParams = -32602;
constexpr int kInternalError = -32603;
constexpr int kServerNotInitialized = -32002;
constexpr int kRequestFailed = -32803;  // a valid request the server declines (a rename refused), with the reason
}  // namespace error

// One message read: its JSON, or why it is not JSON (the server answers a parse error).
struct Incoming {
    enum class Kind { Message, Malformed, Timeout, End } kind = Kind::End;
    nlohmann::json json;
    std::string problem;
};

class Transport {
public:
    Transport(int in, int out) : in_(in), out_(out) {}
    // The next message; Timeout when none is complete within `wait` (nullopt: wait for ever).
    Incoming read(std::optional<std::chrono::milliseconds> wait);
    void write(const nlohmann::json& message);
    // A message already written as JSON text.
    void writeText(const std::string& body);

    // A message larger than this is refused (read past and answered with a parse error).
    static constexpr size_t kMaxMessage = 64u << 20;

private:
    bool fill(std::optional<std::chrono::steady_clock::time_point> deadline);  // false: end or time up
    std::optional<Incoming> take();  // a complete message from buffer_, if there is one

    int in_, out_;
    std::string buffer_;
    bool ended_ = false;
    size_t skipping_ = 0;  // bytes of a refused message still to discard
};

nlohmann::json errorResponse(const nlohmann::json& id, int code, const std::string& message);

}  // namespace psys::lsp
