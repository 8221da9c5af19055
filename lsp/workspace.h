// The workspace index: every `.psys` file under the editor's workspace folders, analysed
// from disk (or from the editor's text where open), so that references, rename and
// workspace symbols reach the files no one has opened. It is built in the background
// after `initialize`, kept current from didChangeWatchedFiles and didSave, and an edit to
// an open file makes the indexed files that import it stale.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "lsp/analysis.h"

namespace psys::lsp {

class WorkspaceIndex {
public:
    static constexpr size_t kMaxFiles = 5000;
    ~WorkspaceIndex();

    // The folders to index (paths); their `.psys` files are found (hidden folders and
    // node_modules skipped) and all made stale.
    void setFolders(const std::vector<std::string>& folders);
    // A file created or changed on disk, or deleted.
    void changed(const std::string& path);
    void removed(const std::string& path);
    // The text of the file `key` (sourceKey) is not what the files importing it read.
    void importChanged(const std::string& key);

    // Collects a finished background analysis, then starts one of what is stale (reading
    // `openTexts()` for the files the editor has open: asked only then). True while one runs.
    bool step(const std::function<SourceOverrides()>& openTexts);
    // Every indexed file's analysis but those whose key is in `skip` (the open documents:
    // their own analyses are the truth), stale ones analysed first; waits for the
    // background one.
    std::vector<const Analysis*> all(const SourceOverrides& open, const std::set<std::string>& skip);
    size_t size() const { return entries_.size(); }

private:
    struct Entry {
        std::string path;
        std::shared_ptr<const Analysis> analysis;
        uint64_t generation = 1;  // counts the times it went stale
        uint64_t analysed = 0;    // the generation `analysis` is of
    };
    struct Job {
        std::vector<std::pair<std::string, uint64_t>> keys;  // and their generations
        std::shared_ptr<std::atomic<bool>> cancelled;
        std::future<std::vector<Analysis>> result;
    };
    void collect();  // waits for the job, if any, and keeps what is still current

    std::map<std::string, Entry> entries_;  // by sourceKey
    std::optional<Job> job_;
};

}  // namespace psys::lsp
