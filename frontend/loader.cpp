#include "frontend/loader.h"

#include <dlfcn.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <algorithm>
#include <map>

#include <fmt/format.h>

#include "frontend/parse.h"

namespace psys {

std::optional<std::string> readSourceFile(const std::filesystem::path& path, std::string& error) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) {
        error = "it is a directory";
        return std::nullopt;
    }
    // Only a regular file has an end: a device or a pipe (`/dev/zero`) is not read.
    if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec)) {
        error = "it is not a regular file";
        return std::nullopt;
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        error = std::strerror(errno);
        return std::nullopt;
    }
    std::string text(kMaxSourceBytes + 1, '\0');
    in.read(text.data(), static_cast<std::streamsize>(text.size()));
    text.resize(static_cast<size_t>(in.gcount()));
    if (text.size() > kMaxSourceBytes) {
        error = fmt::format("it is larger than {} bytes, the most a source file may be", kMaxSourceBytes);
        return std::nullopt;
    }
    return text;
}

namespace {

namespace fs = std::filesystem;

// The file an import names: the library's for `std/…` (the first directory that has
// it; else empty, with where it looked in `looked`), else beside its importer.
fs::path importTarget(const std::string& path, const fs::path& importer, const SourceManager& sources,
                      std::string& looked) {
    if (!path.starts_with("std/")) return (importer.parent_path() / path).lexically_normal();
    std::error_code ec;
    std::vector<fs::path> dirs = sources.libraryPath();  // (the host's first)
    for (fs::path& dir : libraryDirectories()) dirs.push_back(std::move(dir));
    for (const fs::path& dir : dirs) {
        fs::path file = (dir / path).lexically_normal();
        // Named by where it really is (a build tree links share/psys/std to library/std).
        if (fs::exists(file, ec)) return fs::weakly_canonical(file, ec);
        looked += (looked.empty() ? "" : ", ") + dir.string();
    }
    return {};
}

class Loader {
public:
    Loader(SourceManager& sources, DiagnosticEngine& diags, const SourceOverrides* overrides, ParseCache* cache,
           const std::vector<bool>* keep = nullptr)
        : sources_(sources), diags_(diags), overrides_(overrides), cache_(cache), keep_(keep) {}

    std::unique_ptr<ast::Program> run(const std::string& displayPath, std::string text) {
        program_ = std::make_unique<ast::Program>();
        bool ok = loadText(fs::path(displayPath), std::move(text));
        return ok && diags_.errorCount() == 0 ? std::move(program_) : nullptr;
    }

    bool loadText(const fs::path& displayPath, std::string text, SourceRange importedAt = {}) {
        std::string key = canonicalKey(displayPath);
        int file = sources_.add(displayPath.string(), std::move(text));
        sources_.setImportedAt(file, importedAt);
        auto module = parseModule(file, sources_, diags_, cache_, stack_.empty() ? keep_ : nullptr);
        if (!module) return false;
        stack_.push_back({key, displayPath.string()});
        bool ok = true;
        for (auto& decl : module->decls)
            if (decl->kind == ast::DeclKind::Import) ok &= loadImport(static_cast<ast::ImportDecl&>(*decl), displayPath);
        stack_.pop_back();
        // Imports first, so a name declared both in a library and in its importer is
        // reported at the importer's declaration.
        loaded_[key] = static_cast<int>(program_->modules.size());
        program_->modules.push_back(std::move(module));
        return ok;
    }

private:
    static std::string canonicalKey(const fs::path& path) { return sourceKey(path); }

    bool loadImport(ast::ImportDecl& import, const fs::path& importer) {
        if (import.path.empty()) {
            diags_.error(import.pathRange, "an import needs a file name");
            return false;
        }
        std::string looked;
        fs::path target = importTarget(import.path, importer, sources_, looked);
        if (target.empty()) {
            diags_.error(import.pathRange,
                         fmt::format("there is no `{}` in the standard library (looked in {})", import.path,
                                     looked.empty() ? "no directory: none was found" : looked))
                .notes.push_back({import.pathRange, "PSYS_LIBRARY names the directories that hold `std/`"});
            return false;
        }
        std::string key = canonicalKey(target);
        for (size_t i = 0; i < stack_.size(); ++i) {
            if (stack_[i].first != key) continue;
            std::string chain;
            for (size_t j = i; j < stack_.size(); ++j) chain += stack_[j].second + " → ";
            diags_.error(import.pathRange, fmt::format("import cycle: {}{}", chain, target.string()))
                .notes.push_back({import.pathRange, "a file cannot import itself, directly or through others"});
            return false;
        }
        if (auto it = loaded_.find(key); it != loaded_.end()) {
            import.module = it->second;
            return true;
        }
        std::string error;
        std::optional<std::string> text;
        if (auto open = overrides_ ? overrides_->find(key) : SourceOverrides::const_iterator();
            overrides_ && open != overrides_->end())
            text = open->second;
        else
            text = readSourceFile(target, error);
        if (!text) {
            diags_.error(import.pathRange, fmt::format("cannot open imported file `{}`: {}", target.string(), error));
            return false;
        }
        bool ok = loadText(target, std::move(*text), import.pathRange);
        if (auto it = loaded_.find(key); it != loaded_.end()) import.module = it->second;
        return ok;
    }

    SourceManager& sources_;
    DiagnosticEngine& diags_;
    const SourceOverrides* overrides_;
    ParseCache* cache_;
    const std::vector<bool>* keep_;  // the main file's pieces to load
    std::unique_ptr<ast::Program> program_;
    std::map<std::string, int> loaded_;
    std::vector<std::pair<std::string, std::string>> stack_;  // (canonical, display) of files being loaded
};

}  // namespace

std::vector<fs::path> libraryDirectories() {
    std::vector<fs::path> dirs;
    if (const char* env = std::getenv("PSYS_LIBRARY")) {
        std::string list = env;
        for (size_t start = 0; start <= list.size();) {
            size_t end = std::min(list.find(':', start), list.size());
            if (end > start) dirs.emplace_back(list.substr(start, end - start));
            start = end + 1;
        }
    }
    // The running program, then the shared object this code is in where that is another
    // (libpsys.so in a host's process: lib/../share/psys where installed).
    std::error_code ec;
    std::vector<fs::path> selves;
    fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (!ec) selves.push_back(exe);
    Dl_info info;
    if (dladdr(reinterpret_cast<const void*>(&libraryDirectories), &info) && info.dli_fname &&
        info.dli_fname[0] == '/') {
        fs::path object = fs::weakly_canonical(info.dli_fname, ec);
        if (!ec && object != exe) selves.push_back(object);
    }
    for (const fs::path& self : selves)
        for (fs::path dir = self.parent_path(); !dir.empty(); dir = dir.parent_path()) {
            if (fs::is_directory(dir / "share/psys/std", ec)) {
                dirs.push_back(dir / "share/psys");
                break;
            }
            if (dir == dir.root_path()) break;
        }
    return dirs;
}

std::string libraryFileDeclaring(const std::string& name) {
    static const std::map<std::string, std::string> declared = [] {
        std::map<std::string, std::string> names;
        std::error_code ec;
        for (const fs::path& dir : libraryDirectories()) {
            std::vector<fs::path> files;
            for (const auto& entry : fs::directory_iterator(dir / "std", ec))
                if (entry.path().extension() == ".psys") files.push_back(entry.path());
            std::sort(files.begin(), files.end());
            for (const fs::path& file : files) {
                std::string error;
                auto text = readSourceFile(file, error);
                if (!text) continue;
                SourceManager sources;
                DiagnosticEngine quiet(sources);
                auto module = parseModule(sources.add(file.string(), std::move(*text)), sources, quiet);
                if (!module) continue;
                for (const auto& decl : module->decls) {
                    std::string declName;
                    if (auto* c = dynamic_cast<const ast::ConstDecl*>(decl.get())) declName = c->name;
                    else if (auto* f = dynamic_cast<const ast::FnDecl*>(decl.get())) declName = f->name;
                    else if (auto* o = dynamic_cast<const ast::ObjectDecl*>(decl.get())) declName = o->name;
                    if (!declName.empty()) names.emplace(declName, "std/" + file.filename().string());
                }
            }
        }
        return names;
    }();
    auto it = declared.find(name);
    return it == declared.end() ? std::string() : it->second;
}

std::unique_ptr<ast::Program> loadProgram(const std::string& mainPath, SourceManager& sources, DiagnosticEngine& diags) {
    std::string error;
    auto text = readSourceFile(mainPath, error);
    if (!text) {
        diags.error({}, fmt::format("cannot read `{}`: {}", mainPath, error));
        return nullptr;
    }
    return loadProgramFromText(mainPath, std::move(*text), sources, diags);
}

std::unique_ptr<ast::Program> loadProgramFromText(const std::string& displayPath, std::string text,
                                                  SourceManager& sources, DiagnosticEngine& diags,
                                                  const SourceOverrides* overrides, ParseCache* cache,
                                                  const std::vector<bool>* keep) {
    return Loader(sources, diags, overrides, cache, keep).run(displayPath, std::move(text));
}

std::string sourceKey(const std::filesystem::path& path) {
    std::error_code ec;
    fs::path canonical = fs::weakly_canonical(path, ec);
    return (ec ? path.lexically_normal() : canonical).string();
}

}  // namespace psys
