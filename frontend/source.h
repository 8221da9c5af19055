// Source text and locations.
//
// Every AST node and every diagnostic carries a SourceRange: a file and a half-open byte
// range in it. Line and column are computed only when a diagnostic is printed.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace psys {

struct SourceRange {
    int file = -1;        // index into SourceManager; -1: no location (command line, built-in)
    uint32_t begin = 0;   // byte offsets, half-open
    uint32_t end = 0;

    bool valid() const { return file >= 0; }
    static SourceRange join(SourceRange a, SourceRange b);
};

struct LineColumn {
    uint32_t line = 1;    // 1-based
    uint32_t column = 1;  // 1-based, in bytes
};

class SourceFile {
public:
    SourceFile(std::string displayPath, std::string text);

    const std::string& path() const { return path_; }
    const std::string& text() const { return text_; }
    LineColumn lineColumn(uint32_t offset) const;
    uint32_t offset(LineColumn at) const;  // the byte offset of a line and column (clamped to the text)
    std::string_view lineText(uint32_t line) const;  // without the line ending

    // UTF-16 code units (the Language Server Protocol's columns) in the text before
    // `offset`: a lead byte counts 1, or 2 from 0xF0 (a surrogate pair), a continuation byte
    // 0. And the first sequence boundary p in [from, limit] with `units` more units before
    // it than before `from` (else `limit`). Both cost at most kUnitStride bytes of scanning,
    // however long the line: a file of one 1 MB line maps positions as fast as any.
    uint32_t utf16Before(uint32_t offset) const;
    uint32_t advanceUtf16(uint32_t from, uint64_t units, uint32_t limit) const;

private:
    static constexpr uint32_t kUnitStride = 64;
    std::string path_;
    std::string text_;
    std::vector<uint32_t> lineStarts_;
    std::vector<uint32_t> unitsAt_;  // unitsAt_[k]: utf16Before(k · kUnitStride)
};

// The largest source file read or parsed (a limit in docs/language.md): a program is
// text a person or a program writes, not a data file.
constexpr size_t kMaxSourceBytes = 1 << 20;

// The offset of the first byte that does not begin a well-formed UTF-8 sequence (overlong
// forms, surrogates and code points past U+10FFFF are not well-formed), or nullopt.
std::optional<uint32_t> firstInvalidUtf8(std::string_view text);

class SourceManager {
public:
    int add(std::string displayPath, std::string text);
    const SourceFile& file(int id) const { return *files_.at(static_cast<size_t>(id)); }
    int count() const { return static_cast<int>(files_.size()); }
    // The import that first loaded file `id` (its path's range in the importer); invalid
    // for the main file. Editors show an imported file's errors at the importer's line.
    SourceRange importedAt(int id) const { return importedAt_.at(static_cast<size_t>(id)); }
    void setImportedAt(int id, SourceRange where) { importedAt_.at(static_cast<size_t>(id)) = where; }
    // Directories `import "std/…"` looks in before libraryDirectories()'s: a host's own
    // (psys_options.library_path). Each holds `std/`.
    const std::vector<std::filesystem::path>& libraryPath() const { return libraryPath_; }
    void setLibraryPath(std::vector<std::filesystem::path> dirs) { libraryPath_ = std::move(dirs); }

private:
    std::vector<std::unique_ptr<SourceFile>> files_;
    std::vector<SourceRange> importedAt_;
    std::vector<std::filesystem::path> libraryPath_;
};

// A file a program names (`@texture("flame.png")`), found beside the program that names
// it, as an import is: relative to the directory of the file `where` is in.
std::filesystem::path besideSource(const SourceManager& sources, SourceRange where, const std::string& name);

}  // namespace psys
