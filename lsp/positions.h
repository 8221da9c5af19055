// Where things are, in the protocol's terms: a position is a 0-based line and a column in
// UTF-16 code units (the protocol's default); the front end counts bytes of UTF-8. And
// documents are named by `file://` URIs, the front end's files by paths.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "frontend/source.h"
#include "lsp/params.h"

namespace psys::lsp {

// The protocol's line and character (UTF-16 units from the line's start) of a byte offset.
struct LineCharacter {
    uint32_t line, character;
};
LineCharacter lineCharacter(const SourceFile& file, uint32_t offset);
nlohmann::json position(const SourceFile& file, uint32_t offset);
nlohmann::json range(const SourceFile& file, uint32_t begin, uint32_t end);
// The byte offset of a protocol position (clamped to the line and the text).
// A position that is not two counts is refused (InvalidParams, naming the field).
uint32_t offsetOf(const SourceFile& file, const Field& position);
uint32_t offsetOf(const SourceFile& file, const nlohmann::json& position);

// `file:///a%20b/c.psys` ↔ `/a b/c.psys`. A URI of another scheme is returned as it is.
std::string pathFromUri(const std::string& uri);
std::string uriFromPath(const std::string& path);

}  // namespace psys::lsp
