#include "watcher.h"

#include <sys/inotify.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>

namespace psys::viewer {

namespace fs = std::filesystem;

Watcher::Watcher() : fd_(inotify_init1(IN_NONBLOCK | IN_CLOEXEC)) {}

Watcher::~Watcher() {
    if (fd_ >= 0) close(fd_);
}

void Watcher::watch(const std::vector<std::string>& files) {
    if (fd_ < 0) return;
    for (auto& [wd, folder] : folders_) inotify_rm_watch(fd_, wd);
    folders_.clear();
    files_.clear();
    std::set<std::string> folders;
    for (const std::string& f : files) {
        std::error_code error;
        fs::path path = fs::absolute(f, error).lexically_normal();
        if (error) continue;
        files_.insert(path.string());
        folders.insert(path.parent_path().string());
    }
    for (const std::string& folder : folders) {
        int wd = inotify_add_watch(fd_, folder.c_str(), IN_CLOSE_WRITE | IN_MOVED_TO | IN_CREATE | IN_DELETE | IN_MOVED_FROM);
        if (wd >= 0) folders_[wd] = folder;
    }
}

bool Watcher::changed() {
    if (fd_ < 0) return false;
    bool any = false;
    alignas(inotify_event) char buffer[8192];
    for (;;) {
        ssize_t n = read(fd_, buffer, sizeof buffer);
        if (n <= 0) break;  // EAGAIN: nothing more
        for (char* p = buffer; p < buffer + n;) {
            auto* event = reinterpret_cast<inotify_event*>(p);
            auto folder = folders_.find(event->wd);
            if (folder != folders_.end() && event->len > 0 &&
                files_.count((fs::path(folder->second) / event->name).lexically_normal().string()))
                any = true;
            p += sizeof(inotify_event) + event->len;
        }
    }
    return any;
}

}  // namespace psys::viewer
