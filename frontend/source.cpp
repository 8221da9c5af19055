#include "frontend/source.h"

#include <algorithm>

namespace psys {

SourceRange SourceRange::join(SourceRange a, SourceRange b) {
    if (!a.valid()) return b;
    if (!b.valid() || a.file != b.file) return a;
    return {a.file, std::min(a.begin, b.begin), std::max(a.end, b.end)};
}

SourceFile::SourceFile(std::string displayPath, std::string text)
    : path_(std::move(displayPath)), text_(std::move(text)) {
    lineStarts_.push_back(0);
    for (uint32_t i = 0; i < text_.size(); ++i)
        if (text_[i] == '\n') lineStarts_.push_back(i + 1);
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

int SourceManager::add(std::string displayPath, std::string text) {
    files_.push_back(std::make_unique<SourceFile>(std::move(displayPath), std::move(text)));
    return count() - 1;
}

}  // namespace psys
