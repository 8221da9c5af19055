// Reading a request's params. A field that is missing, or of the wrong kind, is the
// client's mistake: it is told which field and what was expected, in the protocol's names
// (`position.line`, `textDocument.uri`), never in the JSON library's words.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

namespace psys::lsp {

// Thrown for params the request cannot be answered from; the server answers InvalidParams.
struct InvalidParams : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// A value in the params and the path that names it.
class Field {
public:
    // The params themselves: Field(params, "").
    Field(const nlohmann::json& value, std::string path) : value_(&value), path_(std::move(path)) {}

    // A member that must be there (the value must be an object).
    Field operator[](const char* key) const;
    // A member that may be absent (or null); if it is there it is read like any other.
    std::optional<Field> get(const char* key) const;
    std::string string() const;
    const nlohmann::json& array() const;
    const nlohmann::json& object() const;
    bool boolean() const;
    const nlohmann::json& json() const { return *value_; }
    const std::string& path() const { return path_; }
    // "`path` must be K, not V" (V shortened so that a huge value does not fill the message).
    [[noreturn]] void refuse(const std::string& expected) const;

private:
    const nlohmann::json* value_;
    std::string path_;
};

}  // namespace psys::lsp
