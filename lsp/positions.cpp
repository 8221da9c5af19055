#include "lsp/positions.h"

#include <filesystem>

namespace psys::lsp {

namespace {

// A position's field as a count: a JSON integer, or a number past any file's lines or
// columns (1e300, 2^64) clamped to the largest; a negative or non-numeric one is an error.
uint64_t count(const Field& at, const char* field) {
    Field f = at[field];
    const nlohmann::json& v = f.json();
    if (v.is_number_unsigned()) return v.get<uint64_t>();
    if (v.is_number_integer() && v.get<int64_t>() >= 0) return static_cast<uint64_t>(v.get<int64_t>());
    if (v.is_number_float() && v.get<double>() >= 0) return v.get<double>() >= 1e18 ? UINT64_MAX : static_cast<uint64_t>(v.get<double>());
    f.refuse("a count from 0");
}

}  // namespace

// Columns in UTF-16 units from the line's start (SourceFile keeps a running count).
LineCharacter lineCharacter(const SourceFile& file, uint32_t offset) {
    LineColumn lc = file.lineColumn(offset);
    uint32_t start = file.offset({lc.line, 1});
    uint32_t end = start + static_cast<uint32_t>(file.lineText(lc.line).size());
    return {lc.line - 1, static_cast<uint32_t>(file.utf16Before(std::min(offset, end)) - file.utf16Before(start))};
}

nlohmann::json position(const SourceFile& file, uint32_t offset) {
    LineCharacter at = lineCharacter(file, offset);
    return {{"line", at.line}, {"character", at.character}};
}

nlohmann::json range(const SourceFile& file, uint32_t begin, uint32_t end) {
    return {{"start", position(file, begin)}, {"end", position(file, end)}};
}

uint32_t offsetOf(const SourceFile& file, const nlohmann::json& at) { return offsetOf(file, Field(at, "position")); }

uint32_t offsetOf(const SourceFile& file, const Field& at) {
    uint64_t line = count(at, "line"), character = count(at, "character");
    auto lineNo = static_cast<uint32_t>(std::min<uint64_t>(line + 1, UINT32_MAX));
    if (line >= UINT32_MAX) lineNo = UINT32_MAX;
    uint32_t start = file.offset({lineNo, 1});
    uint32_t end = start + static_cast<uint32_t>(file.lineText(lineNo).size());
    return file.advanceUtf16(start, character, end);
}

std::string pathFromUri(const std::string& uri) {
    const std::string scheme = "file://";
    if (uri.rfind(scheme, 0) != 0) return uri;
    std::string path;
    for (size_t i = scheme.size(); i < uri.size(); ++i) {
        auto hex = [](char c) { return std::isxdigit(static_cast<unsigned char>(c)); };
        if (uri[i] == '%' && i + 2 < uri.size() && hex(uri[i + 1]) && hex(uri[i + 2])) {
            path += static_cast<char>(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
            i += 2;
        } else {
            path += uri[i];
        }
    }
    return path;
}

std::string uriFromPath(const std::string& path) {
    std::error_code ec;
    std::string absolute = std::filesystem::absolute(path, ec).lexically_normal().string();
    if (ec) absolute = path;
    std::string uri = "file://";
    for (unsigned char c : absolute) {
        if (std::isalnum(c) || c == '/' || c == '-' || c == '_' || c == '.' || c == '~') {
            uri += static_cast<char>(c);
        } else {
            static const char* digits = "0123456789ABCDEF";
            uri += '%';
            uri += digits[c >> 4];
            uri += digits[c & 15];
        }
    }
    return uri;
}

}  // namespace psys::lsp
