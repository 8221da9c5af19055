#include "lsp/transport.h"

#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>

namespace psys::lsp {

namespace {

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return s;
}

// The Content-Length of a header block, or nullopt when it has none that is a number.
std::optional<size_t> contentLength(const std::string& header) {
    size_t at = 0;
    while (at < header.size()) {
        size_t end = header.find("\r\n", at);
        if (end == std::string::npos) end = header.size();
        std::string line = header.substr(at, end - at);
        at = end + 2;
        size_t colon = line.find(':');
        if (colon == std::string::npos || lower(line.substr(0, colon)) != "content-length") continue;
        std::string value = line.substr(colon + 1);
        value.erase(0, value.find_first_not_of(" \t"));
        if (value.empty() || value.size() > 12 || !std::all_of(value.begin(), value.end(), ::isdigit)) return std::nullopt;
        return std::stoull(value);
    }
    return std::nullopt;
}

// Where the next `Content-Length:` header begins at or after `from` (any case), or npos.
size_t nextHeader(const std::string& buffer, size_t from) {
    static const std::string name = "content-length:";
    for (size_t at = from; at + name.size() <= buffer.size(); ++at) {
        size_t k = 0;
        while (k < name.size() && std::tolower(static_cast<unsigned char>(buffer[at + k])) == name[k]) ++k;
        if (k == name.size()) return at;
    }
    return std::string::npos;
}

}  // namespace

bool Transport::fill(std::optional<std::chrono::steady_clock::time_point> deadline) {
    if (ended_) return false;
    int timeout = -1;
    if (deadline) {
        auto left = std::chrono::duration_cast<std::chrono::milliseconds>(*deadline - std::chrono::steady_clock::now());
        timeout = static_cast<int>(std::max<long long>(0, left.count()));
    }
    pollfd fd{in_, POLLIN, 0};
    int ready = poll(&fd, 1, timeout);
    if (ready < 0 && errno == EINTR) return true;
    if (ready <= 0) return false;
    char chunk[65536];
    ssize_t n = ::read(in_, chunk, sizeof chunk);
    if (n < 0 && errno == EINTR) return true;
    if (n <= 0) {
        ended_ = true;
        return false;
    }
    size_t got = static_cast<size_t>(n), skip = std::min(skipping_, got);
    skipping_ -= skip;
    buffer_.append(chunk + skip, got - skip);
    return true;
}

std::optional<Incoming> Transport::take() {
    size_t headerEnd = buffer_.find("\r\n\r\n");
    if (headerEnd == std::string::npos) return std::nullopt;
    std::optional<size_t> length = contentLength(buffer_.substr(0, headerEnd));
    size_t body = headerEnd + 4;
    if (!length) {
        // Out of step with the client (a stray newline or NUL between messages, a header
        // without a length): what precedes the next Content-Length header is dropped and
        // answered once, and the messages after it are read as ever.
        size_t next = nextHeader(buffer_, 1);
        buffer_.erase(0, next == std::string::npos ? body : next);
        return Incoming{Incoming::Kind::Malformed, {}, "bytes that are not a message (no Content-Length before them)"};
    }
    if (*length > kMaxMessage) {
        size_t have = std::min(buffer_.size() - body, *length);
        skipping_ = *length - have;
        buffer_.erase(0, body + have);
        return Incoming{Incoming::Kind::Malformed, {}, "a message larger than 64 MiB"};
    }
    if (buffer_.size() - body < *length) return std::nullopt;
    std::string text = buffer_.substr(body, *length);
    buffer_.erase(0, body + *length);
    nlohmann::json json = nlohmann::json::parse(text, nullptr, false);
    if (json.is_discarded()) return Incoming{Incoming::Kind::Malformed, {}, "the message is not JSON"};
    return Incoming{Incoming::Kind::Message, std::move(json), {}};
}

Incoming Transport::read(std::optional<std::chrono::milliseconds> wait) {
    std::optional<std::chrono::steady_clock::time_point> deadline;
    if (wait) deadline = std::chrono::steady_clock::now() + *wait;
    for (;;) {
        if (auto message = take()) return *message;
        if (!fill(deadline)) return Incoming{ended_ ? Incoming::Kind::End : Incoming::Kind::Timeout, {}, {}};
    }
}

void Transport::write(const nlohmann::json& message) {
    // Invalid UTF-8 in a message (a file's bytes in a diagnostic) becomes U+FFFD rather than an exception.
    writeText(message.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
}

void Transport::writeText(const std::string& body) {
    std::string frame = "Content-Length: " + std::to_string(body.size()) + "\r\n\r\n" + body;
    const char* p = frame.data();
    size_t left = frame.size();
    while (left > 0) {
        ssize_t n = ::write(out_, p, left);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return;  // the client is gone; its `exit` or end of input follows
        p += n;
        left -= static_cast<size_t>(n);
    }
}

nlohmann::json errorResponse(const nlohmann::json& id, int code, const std::string& message) {
    return {{"jsonrpc", "2.0"}, {"id", id}, {"error", {{"code", code}, {"message", message}}}};
}

}  // namespace psys::lsp
