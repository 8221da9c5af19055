// Loading a program: the main file and, transitively, every file it imports.
//
// An import path is relative to the importing file, but one that starts with `std/`: that
// is the standard library's (library/std in the sources), found in the library
// directories (libraryDirectories). Each file is loaded once however often it is imported
// (by its canonical path); an import cycle is an error that names the chain of files.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "frontend/ast.h"
#include "frontend/diagnostics.h"

namespace psys {

// Where `import "std/…"` looks, in order: each directory of the environment variable
// PSYS_LIBRARY (separated by `:`), then beside the running program — the first of its
// directory and that directory's ancestors that holds share/psys/std (bin/../share/psys
// where it is installed, build/share/psys from anywhere in a build tree) — then beside
// libpsys.so where the compiler runs in a host's process (lib/../share/psys). A directory
// listed holds `std/`.
std::vector<std::filesystem::path> libraryDirectories();

// The text of a source file, or nullopt with why not in `error` (a directory, a device, a
// file past kMaxSourceBytes, or what the system said).
std::optional<std::string> readSourceFile(const std::filesystem::path& path, std::string& error);

// The standard library's file (`std/forces.psys`) that declares `name` at its top level, or
// empty: for the quick fix that imports it. The library is read once per process.
std::string libraryFileDeclaring(const std::string& name);

// Texts that stand for files, by the files' keys (sourceKey): an editor's open, unsaved
// documents, which an import reads rather than what is on disk.
using SourceOverrides = std::map<std::string, std::string>;
// The key a file is loaded once by: its canonical path where it has one.
std::string sourceKey(const std::filesystem::path& path);

// Returns null when the main file cannot be read or any file has syntax errors.
std::unique_ptr<ast::Program> loadProgram(const std::string& mainPath, SourceManager& sources, DiagnosticEngine& diags);

class ParseCache;

// The same for a main file given as text (tests, the viewer's editor buffer); imports are
// resolved relative to the directory of `displayPath`, and read from `overrides` where
// it holds their text. Every file is parsed through `cache` where one is given
// (frontend/parse_cache.h: an editor's document, analysed after each edit), and only the
// main file's pieces that `keep` flags are in its module where that is given (the language
// server re-checking what an edit touched: lsp/incremental.h).
std::unique_ptr<ast::Program> loadProgramFromText(const std::string& displayPath, std::string text,
                                                  SourceManager& sources, DiagnosticEngine& diags,
                                                  const SourceOverrides* overrides = nullptr,
                                                  ParseCache* cache = nullptr, const std::vector<bool>* keep = nullptr);

}  // namespace psys
