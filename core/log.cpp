#include "core/log.h"

#include <cstdio>
#include <mutex>
#include <string>

namespace psys::core {

namespace {

// Recursive: a host's sink that logs again, or sets another sink, from inside a call.
std::recursive_mutex& sinkMutex() {
    static std::recursive_mutex m;
    return m;
}
std::function<void(LogLevel, std::string_view)>& sink() {
    static std::function<void(LogLevel, std::string_view)> s;
    return s;
}

const char* levelName(LogLevel level) {
    switch (level) {
        case LogLevel::Error: return "error";
        case LogLevel::Warning: return "warning";
        case LogLevel::Note: return "note";
    }
    return "note";
}

}  // namespace

void log(LogLevel level, std::string_view message) {
    std::lock_guard lock(sinkMutex());  // (one message at a time: a host's sink need not be thread-safe)
    if (sink()) {
        auto call = sink();  // (a copy: the sink may replace itself while it runs)
        call(level, message);
        return;
    }
    std::string line = "psys: " + std::string(levelName(level)) + ": " + std::string(message) + "\n";
    std::fputs(line.c_str(), stderr);
}

void setLogSink(std::function<void(LogLevel, std::string_view)> s) {
    std::lock_guard lock(sinkMutex());
    sink() = std::move(s);
}

}  // namespace psys::core
