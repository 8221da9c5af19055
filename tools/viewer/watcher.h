// Tells when a watched file has been saved (inotify, Linux). Folders are watched, not the
// files themselves, so editors that save by writing a new file and renaming it over the old
// one are seen too.
#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

namespace psys::viewer {

class Watcher {
public:
    Watcher();
    ~Watcher();
    Watcher(const Watcher&) = delete;
    Watcher& operator=(const Watcher&) = delete;
    bool ok() const { return fd_ >= 0; }
    // From now on, these files (a source and everything it imports).
    void watch(const std::vector<std::string>& files);
    // Whether a watched file was written, created or renamed into place since the last
    // call. Never blocks.
    bool changed();

private:
    int fd_ = -1;
    std::map<int, std::string> folders_;  // watch descriptor → folder
    std::set<std::string> files_;          // absolute paths
};

}  // namespace psys::viewer
