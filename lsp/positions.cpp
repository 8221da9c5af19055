#include "lsp/positions.h"

#include <filesystem>

namespace psys::lsp {

namespace {

// UTF-16 code units of the UTF-8 sequence that starts with `lead`.
uint32_t utf16Units(unsigned char lead) { return lead >= 0xF0 ? 2 : 1; }
bool continuation(unsigned char c) { return (c & 0xC0) == 0x80; }

}  // namespace

nlohmann::json position(const SourceFile& file, uint32_t offset) {
    LineColumn lc = file.lineColumn(offset);
    std::string_view line = file.lineText(lc.line);
    uint32_t units = 0;
    for (uint32_t i = 0; i + 1 < lc.column && i < line.size(); ++i) {
        auto c = static_cast<unsigned char>(line[i]);
        if (!continuation(c)) units += utf16Units(c);
    }
    return {{"line", lc.line - 1}, {"character", units}};
}

nlohmann::json range(const SourceFile& file, uint32_t begin, uint32_t end) {
    return {{"start", position(file, begin)}, {"end", position(file, end)}};
}

uint32_t offsetOf(const SourceFile& file, const nlohmann::json& at) {
    auto line = at.at("line").get<int64_t>(), character = at.at("character").get<int64_t>();
    if (line < 0 || character < 0) throw nlohmann::json::other_error::create(501, "a negative position", nullptr);
    uint32_t lineNo = static_cast<uint32_t>(std::min<int64_t>(line + 1, UINT32_MAX));
    std::string_view text = file.lineText(lineNo);
    uint32_t bytes = 0;
    for (int64_t units = 0; bytes < text.size() && units < character;) {
        units += utf16Units(static_cast<unsigned char>(text[bytes]));
        ++bytes;
        while (bytes < text.size() && continuation(static_cast<unsigned char>(text[bytes]))) ++bytes;
    }
    return file.offset({lineNo, bytes + 1});
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
