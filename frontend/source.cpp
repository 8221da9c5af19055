#include "frontend/source.h"

#include <algorithm>

namespace psys {

namespace {

uint32_t unitsOf(char c) {
    auto b = static_cast<unsigned char>(c);
    return (b & 0xC0) == 0x80 ? 0 : b >= 0xF0 ? 2 : 1;
}
bool continuation(char c) { return (static_cast<unsigned char>(c) & 0xC0) == 0x80; }

}  // namespace

SourceRange SourceRange::join(SourceRange a, SourceRange b) {
    if (!a.valid()) return b;
    if (!b.valid() || a.file != b.file) return a;
    return {a.file, std::min(a.begin, b.begin), std::max(a.end, b.end)};
}

SourceFile::SourceFile(std::string displayPath, std::string text)
    : path_(std::move(displayPath)), text_(std::move(text)) {
    // A line ends at \n, \r\n or a lone \r (old Mac files): every diagnostic on its own line.
    lineStarts_.push_back(0);
    for (uint32_t i = 0; i < text_.size(); ++i)
        if (text_[i] == '\n' || (text_[i] == '\r' && (i + 1 == text_.size() || text_[i + 1] != '\n')))
            lineStarts_.push_back(i + 1);
    uint32_t units = 0;
    for (uint32_t i = 0; i <= text_.size(); ++i) {
        if (i % kUnitStride == 0) unitsAt_.push_back(units);
        if (i < text_.size()) units += unitsOf(text_[i]);
    }
}

uint32_t SourceFile::utf16Before(uint32_t offset) const {
    offset = std::min<uint32_t>(offset, static_cast<uint32_t>(text_.size()));
    uint32_t k = offset / kUnitStride, units = unitsAt_[k];
    for (uint32_t i = k * kUnitStride; i < offset; ++i) units += unitsOf(text_[i]);
    return units;
}

uint32_t SourceFile::advanceUtf16(uint32_t from, uint64_t units, uint32_t limit) const {
    limit = std::min<uint32_t>(limit, static_cast<uint32_t>(text_.size()));
    if (from >= limit) return limit;
    uint64_t target = utf16Before(from) + units;
    // The last checkpoint in (from, limit] still short of the target: scan from there.
    uint32_t first = from / kUnitStride + 1, last = limit / kUnitStride;
    uint32_t p = from;
    if (first <= last) {
        auto begin = unitsAt_.begin() + first, end = unitsAt_.begin() + last + 1;
        auto it = std::lower_bound(begin, end, target);  // the first checkpoint at or past it
        if (it != begin) p = static_cast<uint32_t>(it - unitsAt_.begin() - 1) * kUnitStride;
    }
    uint64_t at = utf16Before(p);
    while (p < limit && (at < target || continuation(text_[p]))) at += unitsOf(text_[p++]);
    return p;
}

LineColumn SourceFile::lineColumn(uint32_t offset) const {
    auto it = std::upper_bound(lineStarts_.begin(), lineStarts_.end(), offset);
    auto line = static_cast<uint32_t>(it - lineStarts_.begin());
    return {line, offset - lineStarts_[line - 1] + 1};
}

uint32_t SourceFile::offset(LineColumn at) const {
    if (at.line == 0) return 0;
    if (at.line > lineStarts_.size()) return static_cast<uint32_t>(text_.size());
    uint32_t start = lineStarts_[at.line - 1];
    return std::min<uint32_t>(start + (at.column > 0 ? at.column - 1 : 0), static_cast<uint32_t>(text_.size()));
}

std::string_view SourceFile::lineText(uint32_t line) const {
    if (line == 0 || line > lineStarts_.size()) return {};
    uint32_t begin = lineStarts_[line - 1];
    uint32_t end = line < lineStarts_.size() ? lineStarts_[line] : static_cast<uint32_t>(text_.size());
    std::string_view view(text_.data() + begin, end - begin);
    while (!view.empty() && (view.back() == '\n' || view.back() == '\r')) view.remove_suffix(1);
    return view;
}

std::optional<uint32_t> firstInvalidUtf8(std::string_view text) {
    auto byte = [&](size_t i) { return i < text.size() ? static_cast<unsigned char>(text[i]) : 0u; };
    for (size_t i = 0; i < text.size();) {
        unsigned c = byte(i);
        size_t length = c < 0x80 ? 1 : c >= 0xC2 && c <= 0xDF ? 2 : c >= 0xE0 && c <= 0xEF ? 3 : c >= 0xF0 && c <= 0xF4 ? 4 : 0;
        if (length == 0) return static_cast<uint32_t>(i);
        // The second byte's range excludes overlong forms, surrogates and what lies past U+10FFFF.
        unsigned lo = c == 0xE0 ? 0xA0 : c == 0xF0 ? 0x90 : 0x80;
        unsigned hi = c == 0xED ? 0x9F : c == 0xF4 ? 0x8F : 0xBF;
        for (size_t k = 1; k < length; ++k) {
            unsigned b = byte(i + k);
            if (k == 1 ? (b < lo || b > hi) : (b & 0xC0) != 0x80) return static_cast<uint32_t>(i);
        }
        i += length;
    }
    return std::nullopt;
}

int SourceManager::add(std::string displayPath, std::string text) {
    files_.push_back(std::make_unique<SourceFile>(std::move(displayPath), std::move(text)));
    importedAt_.emplace_back();
    return count() - 1;
}

std::filesystem::path besideSource(const SourceManager& sources, SourceRange where, const std::string& name) {
    std::filesystem::path dir = where.valid() ? std::filesystem::path(sources.file(where.file).path()).parent_path() : "";
    return (dir / name).lexically_normal();
}

}  // namespace psys
