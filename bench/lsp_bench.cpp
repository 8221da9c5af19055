// The language server on big inputs: a generated file of 20,005 lines (2,500 objects) and a
// generated workspace of 20 files of 1,000 lines, driven in process as a client would
// (didOpen, didChange, requests; the server's own background analysis and debounce 0).
//   build/bench/psys_lsp_bench [--repeat N]
// Prints, per measure, the median and the slowest of N tries in milliseconds:
//   open → diagnostics      didOpen of the big file until its diagnostics are published
//   edit → diagnostics      an edit inside one object until the new diagnostics are published
//   edit → the passes'      … and until the compiler's passes have run on it (their warnings published)
//   hover while analysing   a hover sent 200 ms after an edit, while its analysis runs
//   hover, symbols, format  on an analysed text, and right after an edit; formatting a text laid
//                           out already, and one with a line to re-indent
//   index, references, rename   the workspace: the index built, a function's uses across 20 files
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <unistd.h>

#include <CLI/CLI.hpp>

#include "lsp/positions.h"
#include "lsp/server.h"

namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;
using psys::lsp::Server;

double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// 8 lines an object; `n` objects after a 5-line head.
std::string bigFile(int objects, const std::string& prefix = "o") {
    std::string s = "extern sparks: float = 50;\nfn gravity(m: float) -> vec3 = vec3(0, -9.82 * m, 0);\n"
                    "fn drag(v: vec3, k: float) -> vec3 = -v * k;\n\n";
    for (int i = 0; i < objects; ++i) {
        std::string n = prefix + std::to_string(i);
        s += "object " + n + "(ivel: vec3) {\n";
        s += "    pos = origin + integrate(vel);\n";
        s += "    vel = snapshot(ivel) + integrate(gravity(0.3) + drag(vel, 0.1));\n";
        s += "    tint = vec4(0.5, 0.25 + 0.5 * age, 1, 1);\n";
        s += "    point(pos, tint, 2);\n";
        s += "    kill when age > " + std::to_string(1 + i % 7) + ";\n";
        s += "}\n\n";
    }
    s += "spawn " + prefix + "0(vec3(0, 15, 0));\n";
    return s;
}

struct Client {
    std::vector<json> out;
    // Every message is written out as psysc lsp's transport would (its JSON text); the
    // bench keeps notifications and small answers to look at.
    size_t written = 0;
    Server server{psys::lsp::ServerOptions{.debounce = std::chrono::milliseconds(0), .version = "bench"},
                  [this](const json& m) {
                      written += m.dump().size();
                      if (!m.contains("result") || m["result"].size() < 100) out.push_back(m);
                  },
                  [this](const std::string& text) { written += text.size(); }};
    int id = 1;

    json request(const std::string& method, json params) {
        out.clear();
        int mine = id++;
        server.handle({{"jsonrpc", "2.0"}, {"id", mine}, {"method", method}, {"params", std::move(params)}});
        for (const json& m : out)
            if (m.contains("id") && m["id"] == mine) return m;
        return nullptr;
    }
    void notify(const std::string& method, json params) {
        server.handle({{"jsonrpc", "2.0"}, {"method", method}, {"params", std::move(params)}});
    }
    bool published(const std::string& uri, int version) const {
        for (const json& m : out)
            if (m.value("method", "") == "textDocument/publishDiagnostics" && m["params"]["uri"] == uri &&
                m["params"].value("version", -1) == version)
                return true;
        return false;
    }
    // Runs the server's loop (as psysc lsp's would) until `done`.
    template <typename F>
    void until(F done) {
        while (!done()) {
            server.idle();
            std::this_thread::sleep_for(std::chrono::microseconds(200));
        }
    }
};

struct Row {
    std::string what;
    std::vector<double> ms;
};

void print(const std::vector<Row>& rows) {
    std::printf("%-46s %10s %10s\n", "measure", "median ms", "slowest ms");
    for (Row r : rows) {
        std::sort(r.ms.begin(), r.ms.end());
        std::printf("%-46s %10.1f %10.1f\n", r.what.c_str(), r.ms[r.ms.size() / 2], r.ms.back());
    }
}

json at(int line, int character) { return {{"line", line}, {"character", character}}; }

void bigFileRows(int repeat, const std::filesystem::path& dir, std::vector<Row>& rows) {
    std::string text = bigFile(2500);
    std::string path = (dir / "big.psys").string(), uri = psys::lsp::uriFromPath(path);
    std::ofstream(path) << text;
    Row open{"open → diagnostics (20,005 lines)", {}}, edit{"edit → diagnostics", {}},
        passes{"edit → the passes' warnings too", {}}, during{"hover 200 ms after an edit", {}},
        hover{"hover (analysed)", {}}, symbols{"documentSymbol (analysed)", {}}, symbolsEdited{"documentSymbol after an edit", {}},
        format{"formatting (laid out already)", {}}, reformat{"formatting (a line to re-indent)", {}},
        hoverEdited{"hover right after an edit", {}};
    for (int r = 0; r < repeat; ++r) {
        Client c;
        c.request("initialize", json::object());
        auto t = Clock::now();
        c.notify("textDocument/didOpen", {{"textDocument", {{"uri", uri}, {"version", 1}, {"text", text}}}});
        c.until([&] { return c.published(uri, 1); });
        open.ms.push_back(msSince(t));
        json doc = {{"uri", uri}};
        t = Clock::now();
        c.request("textDocument/hover", {{"textDocument", doc}, {"position", at(5006, 40)}});
        hover.ms.push_back(msSince(t));
        t = Clock::now();
        c.request("textDocument/documentSymbol", {{"textDocument", doc}});
        symbols.ms.push_back(msSince(t));
        t = Clock::now();
        c.request("textDocument/formatting", {{"textDocument", doc}, {"options", {{"tabSize", 4}, {"insertSpaces", true}}}});
        format.ms.push_back(msSince(t));
        // An edit inside object o625 (lines 5004–5010: its `kill when age > …`), then its diagnostics.
        int version = 2;
        auto change = [&](const std::string& with) {
            c.out.clear();
            json range = {{"start", at(5009, 20)}, {"end", at(5009, 21)}};
            json changes = json::array({json{{"range", range}, {"text", with}}});
            c.notify("textDocument/didChange",
                     {{"textDocument", {{"uri", uri}, {"version", version}}}, {"contentChanges", changes}});
        };
        change("9");
        t = Clock::now();
        c.until([&] { return c.published(uri, version); });
        edit.ms.push_back(msSince(t));
        // (The front end's diagnostics come first where the passes are slow; theirs after.)
        c.until([&] { return !c.server.busy(); });
        passes.ms.push_back(msSince(t));
        ++version;
        change("8");
        t = Clock::now();
        c.request("textDocument/hover", {{"textDocument", doc}, {"position", at(5006, 40)}});
        hoverEdited.ms.push_back(msSince(t));
        c.until([&] { return c.published(uri, version); });
        ++version;
        change("7");
        t = Clock::now();
        c.request("textDocument/documentSymbol", {{"textDocument", doc}});
        symbolsEdited.ms.push_back(msSince(t));
        c.until([&] { return c.published(uri, version); });
        ++version;
        change("6");
        c.server.idle();  // the analysis starts in the background
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
        t = Clock::now();
        c.request("textDocument/hover", {{"textDocument", doc}, {"position", at(5006, 40)}});
        during.ms.push_back(msSince(t));
        c.until([&] { return !c.server.busy(); });
        // A line indented two spaces too far: the layout changes the text, and its tokens are checked.
        ++version;
        json indent = {{"range", {{"start", at(5009, 0)}, {"end", at(5009, 0)}}}, {"text", "  "}};
        c.notify("textDocument/didChange", {{"textDocument", {{"uri", uri}, {"version", version}}},
                                            {"contentChanges", json::array({indent})}});
        c.until([&] { return !c.server.busy() && !c.server.nextDeadline(); });
        t = Clock::now();
        json edits = c.request("textDocument/formatting", {{"textDocument", doc}, {"options", {{"tabSize", 4}, {"insertSpaces", true}}}});
        reformat.ms.push_back(msSince(t));
        if (edits["result"].size() != 1) std::fprintf(stderr, "formatting: %zu edits, not 1\n", edits["result"].size());
    }
    for (Row* row : {&open, &edit, &passes, &during, &hoverEdited, &hover, &symbols, &symbolsEdited, &format, &reformat})
        rows.push_back(*row);
}

void workspaceRows(int repeat, const std::filesystem::path& dir, std::vector<Row>& rows) {
    // 20 files of about 1,000 lines: a library, and 19 files that import it and use its function.
    std::filesystem::path ws = dir / "ws";
    std::filesystem::create_directories(ws);
    std::string lib = "fn lift(h: float) -> vec3 = vec3(0, h, 0);\n";
    std::ofstream(ws / "lib.psys") << lib + bigFile(124, "l");
    for (int f = 1; f < 20; ++f) {
        std::string text = "import \"lib.psys\";\nobject user" + std::to_string(f) +
                           " {\n    pos = origin + lift(2);\n    point(pos, white, 1);\n}\n" + bigFile(124, "f" + std::to_string(f) + "_");
        std::ofstream(ws / ("f" + std::to_string(f) + ".psys")) << text;
    }
    std::string uri = psys::lsp::uriFromPath((ws / "lib.psys").string());
    Row index{"workspace: index of 20 files × 1,000 lines", {}}, refs{"references across the workspace", {}},
        rename{"rename across the workspace", {}};
    for (int r = 0; r < repeat; ++r) {
        Client c;
        auto t = Clock::now();
        c.request("initialize", {{"workspaceFolders", {{{"uri", psys::lsp::uriFromPath(ws.string())}, {"name", "ws"}}}}});
        std::ifstream in(ws / "lib.psys");
        std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        c.notify("textDocument/didOpen", {{"textDocument", {{"uri", uri}, {"version", 1}, {"text", text}}}});
        c.server.idle();  // (starts the index in the background)
        c.until([&] { return !c.server.busy(); });
        index.ms.push_back(msSince(t));
        json params = {{"textDocument", {{"uri", uri}}}, {"position", at(0, 4)}};
        t = Clock::now();
        json found = c.request("textDocument/references", params);
        refs.ms.push_back(msSince(t));
        if (found["result"].size() != 20) std::fprintf(stderr, "references: %zu, not 20\n", found["result"].size());
        params["newName"] = "rise";
        t = Clock::now();
        c.request("textDocument/rename", params);
        rename.ms.push_back(msSince(t));
    }
    for (Row* row : {&index, &refs, &rename}) rows.push_back(*row);
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"the language server on a 20,005-line file and a 20-file workspace"};
    int repeat = 5;
    app.add_option("--repeat", repeat, "tries of each measure (the median and the slowest are printed)")->check(CLI::Range(1, 100));
    CLI11_PARSE(app, argc, argv);
    std::filesystem::path dir = std::filesystem::temp_directory_path() / ("psys_lsp_bench_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    std::vector<Row> rows;
    bigFileRows(repeat, dir, rows);
    workspaceRows(repeat, dir, rows);
    std::filesystem::remove_all(dir);
    print(rows);
}
