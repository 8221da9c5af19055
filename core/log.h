// What the libraries have to say outside a call's result — a JIT session's error, a GL
// debug message, a setting that could not be honoured — goes through one function: to
// standard error, unless a host set a sink of its own (psys_set_log: a game's console).
// Process-wide, as the JIT's sessions and GL's debug output are; safe from any thread.
#pragma once

#include <functional>
#include <string_view>

namespace psys::core {

enum class LogLevel { Error, Warning, Note };

// Says `message` (one line, no newline) through the sink.
void log(LogLevel level, std::string_view message);
// The sink from now on; an empty function: standard error again.
void setLogSink(std::function<void(LogLevel, std::string_view)> sink);

}  // namespace psys::core
