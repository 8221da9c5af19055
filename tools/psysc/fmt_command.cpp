#include "fmt_command.h"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <optional>

#include <fmt/format.h>

#include "frontend/format.h"
#include "frontend/loader.h"

namespace psys::tools {

namespace {

namespace fs = std::filesystem;

// The 1-based line where two texts first differ.
size_t firstDifferentLine(const std::string& a, const std::string& b) {
    size_t line = 1;
    for (size_t i = 0; i < a.size() && i < b.size() && a[i] == b[i]; ++i) line += a[i] == '\n';
    return line;
}

// Replaces the file at `path` by `text` as editors do: through a symbolic link, the file
// it names (the link stays a link); a file with other hard links, in place (a new file
// would leave them the old text); else through a file beside it, renamed over it, so a
// failure leaves the old one whole. Returns why it could not, or nothing.
std::optional<std::string> writeBack(const std::string& path, const std::string& text) {
    std::error_code ec;
    fs::path target = fs::canonical(path, ec);
    if (ec) return ec.message();
    if (fs::hard_link_count(target, ec) > 1 && !ec) {
        std::ofstream out(target, std::ios::binary | std::ios::trunc);
        out << text;
        if (!out.flush()) return std::string(std::strerror(errno));
        return std::nullopt;
    }
    fs::path temporary = target.string() + ".psysfmt~";
    {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        if (!out) return "cannot create `" + temporary.string() + "`: " + std::strerror(errno);
        out << text;
        if (!out.flush()) {
            std::string why = std::strerror(errno);
            fs::remove(temporary, ec);
            return why;
        }
    }
    fs::permissions(temporary, fs::status(target, ec).permissions(), ec);
    std::error_code renamed;
    fs::rename(temporary, target, renamed);
    if (!renamed) return std::nullopt;
    fs::remove(temporary, ec);  // (its own failure is not the one to report)
    return renamed.message();
}

std::optional<std::string> readInput(const std::string& path, std::string& error) {
    if (path != "-") return readSourceFile(path, error);
    return std::string(std::istreambuf_iterator<char>(std::cin), std::istreambuf_iterator<char>());
}

}  // namespace

int formatFiles(const FormatOptions& options) {
    bool failed = false;
    for (const std::string& path : options.files) {
        std::string error;
        auto text = readInput(path, error);
        if (!text) {
            std::cerr << "psysc: error: cannot read `" << path << "`: " << error << "\n";
            failed = true;
            continue;
        }
        SourceManager sources;
        DiagnosticEngine diags(sources);
        int file = sources.add(path == "-" ? "<stdin>" : path, *text);
        LayoutOptions layout;
        layout.width = options.width;
        auto formatted = formatSource(file, sources, diags, layout);
        diags.print(std::cerr, options.colour);
        if (!formatted) {
            std::cerr << "psysc: `" << (path == "-" ? "<stdin>" : path) << "` is not formatted: fix its syntax first\n";
            failed = true;
            continue;
        }
        bool same = *formatted == *text;
        if (options.check) {
            if (!same) {
                std::cout << fmt::format("{}: not formatted (from line {}; `psysc fmt --write` formats it)\n", path,
                                         firstDifferentLine(*text, *formatted));
                failed = true;
            }
        } else if (options.write && path != "-") {
            if (auto why = same ? std::nullopt : writeBack(path, *formatted)) {
                std::cerr << "psysc: error: cannot write `" << path << "`: " << *why << "\n";
                failed = true;
            }
        } else {
            std::cout << *formatted;
        }
    }
    return failed ? 1 : 0;
}

}  // namespace psys::tools
