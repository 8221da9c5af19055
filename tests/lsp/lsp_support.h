// What the language server's tests share: a small fireworks program, offsets in a text,
// a temporary directory, and a server session in-process.
#pragma once

#include <doctest/doctest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <functional>
#include <sstream>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lsp/analysis.h"
#include "lsp/features.h"
#include "lsp/server.h"

namespace psys::lsp::test {

using nlohmann::json;

// Everything an analysis answers from, as text: the index (every name's and expression's
// range, hover, definition and token; scopes, file-scope names, members), the outline,
// the hints and the diagnostics (with their notes and fixes, and how many are hidden).
inline std::string everything(const Analysis& a) {
    std::string out;
    auto range = [](SourceRange r) { return fmt::format("{}:{}-{}", r.file, r.begin, r.end); };
    for (const Occurrence& o : a.occurrences)
        out += fmt::format("{} {} {} {}\n", range(o.range), o.hover ? *o.hover : "", o.definition ? range(*o.definition) : "",
                           static_cast<int>(o.token.type));
    std::function<void(const std::vector<Symbol>&)> symbols = [&](const std::vector<Symbol>& list) {
        for (const Symbol& s : list) {
            out += fmt::format("symbol {} {} {} {}\n", s.name, s.detail, range(s.range), range(s.selection));
            symbols(s.children);
        }
    };
    symbols(a.symbols);
    auto names = [&](const std::vector<Name>& list) {
        for (const Name& n : list) out += fmt::format("  {} {} {} {}\n", n.label, n.detail, n.documentation, int(n.kind));
    };
    for (const Scope& s : a.scopes) out += fmt::format("scope {} {}\n", range(s.range), s.pure), names(s.names);
    out += "globals\n", names(a.globals);
    for (const auto& [object, members] : a.members) out += "members " + object + "\n", names(members);
    for (SourceRange r : a.integrating) out += "integrating " + range(r) + "\n";
    for (const Hint& h : a.hints) out += fmt::format("hint {} {}\n", range(h.at), h.label);
    for (const Diagnostic& d : a.diagnostics) {
        out += fmt::format("diagnostic {} {} {}\n", range(d.range), d.message, d.focus ? int(*d.focus) : -1);
        for (const DiagnosticNote& n : d.notes) out += fmt::format("  note {} {}\n", range(n.range), n.message);
        for (const FixIt& f : d.fixes) out += fmt::format("  fix {} {} {}\n", f.title, range(f.range), f.replacement);
    }
    out += fmt::format("hidden {} {}\n", a.hiddenErrors, a.hiddenWarnings);
    return out;
}

inline std::string slurp(const std::string& path) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

inline const char* kFireworks = R"(extern sparks: float = 50;
fn gravity(m: float) -> vec3 = vec3(0, -9.82 * m, 0);
object rocket(ivel: vec3) {
    pos = origin + integrate(vel);
    vel = snapshot(ivel) + integrate(gravity(0.3));
    point(pos, white, 2);
    emit spark(pos) at sparks per second;
    kill when vel.y < 0;
    object spark(ipos: vec3) {
        pos = snapshot(ipos) + integrate(rocket.vel);
        point(pos, mix(green, black, age), 2);
        kill when age > 1;
    }
}
spawn rocket(vec3(0, 15, 0));
)";

// The byte offset of the `n`-th occurrence of `needle` (plus `shift`).
inline uint32_t at(const std::string& text, const std::string& needle, int n = 1, int shift = 0) {
    size_t p = std::string::npos;
    for (int i = 0; i < n; ++i) p = text.find(needle, p == std::string::npos ? 0 : p + 1);
    REQUIRE(p != std::string::npos);
    return static_cast<uint32_t>(p + static_cast<size_t>(shift));
}

inline std::string hoverText(const Analysis& a, uint32_t offset) {
    json h = hover(a, offset);
    return h.is_null() ? std::string() : h["contents"]["value"].get<std::string>();
}

inline std::vector<std::string> labels(const json& completion) {
    std::vector<std::string> out;
    for (const json& item : completion["items"]) out.push_back(item["label"]);
    return out;
}

inline bool has(const std::vector<std::string>& list, const std::string& x) {
    return std::find(list.begin(), list.end(), x) != list.end();
}

struct TempDir {
    std::filesystem::path path;
    TempDir() {
        char name[] = "/tmp/psys_lsp_XXXXXX";
        path = mkdtemp(name);
    }
    ~TempDir() { std::filesystem::remove_all(path); }
    std::string write(const std::string& name, const std::string& text) const {
        std::ofstream(path / name) << text;
        return (path / name).string();
    }
};


// Options whose reads always wait for the analysis of the text they ask about: how fast an
// analysis is (a sanitizer build, a loaded machine) decides nothing in a test. (The reads
// that do not wait are tested with SlowSession.)
inline ServerOptions exactReads(ServerOptions options = {}) {
    options.quickAnalysisMs = std::numeric_limits<double>::infinity();
    return options;
}

struct Session {
    std::vector<json> out;
    Server server{exactReads(), [this](const json& m) { out.push_back(m); }};
    json request(int id, const std::string& method, json params = json::object()) {
        out.clear();
        server.handle({{"jsonrpc", "2.0"}, {"id", id}, {"method", method}, {"params", params}});
        for (const json& m : out)
            if (m.contains("id") && m["id"] == id) return m;
        return nullptr;
    }
};


// A server whose every analysis counts as slow and whose edits wait a minute to be
// analysed: reads answer from the last analysis. `request` returns the result alone.
struct SlowSession {
    std::vector<json> out;
    Server server{slow(), [this](const json& m) { out.push_back(m); }};
    static ServerOptions slow() {
        ServerOptions options;
        options.debounce = std::chrono::milliseconds(60000);
        options.quickAnalysisMs = 0;
        return options;
    }
    json request(int id, const std::string& method, json params) {
        out.clear();
        server.handle({{"jsonrpc", "2.0"}, {"id", id}, {"method", method}, {"params", std::move(params)}});
        for (const json& m : out)
            if (m.contains("id") && m["id"] == id) return m["result"];
        return json();
    }
};

}  // namespace psys::lsp::test
