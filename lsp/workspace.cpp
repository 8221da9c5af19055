#include "lsp/workspace.h"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace psys::lsp {

namespace fs = std::filesystem;

namespace {

std::string readFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

// The file's text: the editor's where it is open, else the disk's.
std::string textOf(const std::string& path, const SourceOverrides& open) {
    auto it = open.find(sourceKey(path));
    return it != open.end() ? it->second : readFile(path);
}

AnalyzeOptions indexOptions(const SourceOverrides* open, const std::atomic<bool>* cancelled) {
    AnalyzeOptions options;
    options.open = open;
    options.cancelled = cancelled;
    options.passes = false;  // names and places only
    return options;
}

}  // namespace

WorkspaceIndex::~WorkspaceIndex() {
    if (job_) job_->cancelled->store(true);  // (its future waits for it to stop)
}

void WorkspaceIndex::setFolders(const std::vector<std::string>& folders) {
    // A folder as wide as a home directory is not walked for ever: the first 200,000
    // entries are looked at, the first kMaxFiles files indexed.
    size_t seen = 0;
    for (const std::string& folder : folders) {
        std::error_code ec;
        fs::recursive_directory_iterator it(folder, fs::directory_options::skip_permission_denied, ec), end;
        for (; !ec && it != end && ++seen < 200000 && entries_.size() < kMaxFiles; it.increment(ec)) {
            std::string name = it->path().filename().string();
            if (it->is_directory(ec) && (name.starts_with(".") || name == "node_modules")) {
                it.disable_recursion_pending();
                continue;
            }
            if (it->is_regular_file(ec) && it->path().extension() == ".psys") changed(it->path().string());
        }
    }
}

void WorkspaceIndex::changed(const std::string& path) {
    Entry& e = entries_[sourceKey(path)];
    e.path = path;
    ++e.generation;
    // Files importing it read it too.
    importChanged(sourceKey(path));
}

void WorkspaceIndex::removed(const std::string& path) {
    entries_.erase(sourceKey(path));
    importChanged(sourceKey(path));
}

void WorkspaceIndex::importChanged(const std::string& key) {
    // An entry not analysed yet, or being analysed now, may import it too (what it reads
    // of it may be the text before this change): it is analysed again.
    for (auto& [k, e] : entries_)
        if (!e.analysis || e.analysed != e.generation || e.analysis->imported.count(key)) ++e.generation;
}

void WorkspaceIndex::collect() {
    if (!job_) return;
    Job job = std::move(*job_);
    job_.reset();
    std::vector<Analysis> done = job.result.get();
    for (size_t i = 0; i < done.size(); ++i) {
        auto it = entries_.find(job.keys[i].first);
        if (it == entries_.end() || it->second.generation != job.keys[i].second) continue;  // changed since
        it->second.analysis = std::make_shared<const Analysis>(std::move(done[i]));
        it->second.analysed = job.keys[i].second;
    }
}

bool WorkspaceIndex::step(const std::function<SourceOverrides()>& openTexts) {
    if (job_ && job_->result.wait_for(std::chrono::seconds(0)) == std::future_status::ready) collect();
    if (job_) return true;
    std::vector<std::pair<std::string, uint64_t>> stale;
    std::vector<std::string> paths;
    for (const auto& [key, e] : entries_)
        if (e.analysed != e.generation) stale.push_back({key, e.generation}), paths.push_back(e.path);
    if (stale.empty()) return false;
    SourceOverrides open = openTexts();
    auto cancelled = std::make_shared<std::atomic<bool>>(false);
    job_ = Job{stale, cancelled, std::async(std::launch::async, [paths, open, cancelled] {
                   std::vector<Analysis> out;
                   for (const std::string& path : paths) {
                       if (cancelled->load()) break;
                       out.push_back(analyze(path, textOf(path, open), indexOptions(&open, cancelled.get())));
                   }
                   return out;
               })};
    return true;
}

std::vector<const Analysis*> WorkspaceIndex::all(const SourceOverrides& open, const std::set<std::string>& skip) {
    collect();
    std::vector<const Analysis*> out;
    for (auto& [key, e] : entries_) {
        if (skip.count(key)) continue;
        if (e.analysed != e.generation) {
            e.analysis = std::make_shared<const Analysis>(analyze(e.path, textOf(e.path, open), indexOptions(&open, nullptr)));
            e.analysed = e.generation;
        }
        out.push_back(e.analysis.get());
    }
    return out;
}

}  // namespace psys::lsp
