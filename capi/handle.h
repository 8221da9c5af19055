// The C API's handle: a running system however it was made — compiled from source (a
// host::Session: capi/compile.cpp) or linked in ahead of time (capi/aot.cpp). What runs
// and reads a system (capi/runtime.cpp) sees only rt::System.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "capi/error.h"
#include "rt/system.h"

struct psys_system {
    virtual ~psys_system() = default;
    virtual psys::rt::System& system() = 0;
    const psys::rt::System& system() const { return const_cast<psys_system*>(this)->system(); }
    // Compiles `source` (or the file again, where null) and takes over the running objects.
    virtual psys_error* reload(const char* source) = 0;

    std::vector<psys::capi::OwnedDiagnostic> warnings;  // of the latest compilation that took
    // The spelled types of externs and triggers (psys_input::type), made at each compilation.
    std::vector<std::string> externTypes, triggerTypes;
    std::vector<std::string> eventNames;  // psys_event_name's
    std::vector<float> events;             // psys_read_events': kept, so that reading them allocates nothing
    // The stats read last (psys_get_stats, psys_get_type_stats): kept, so that reading them
    // every frame allocates nothing.
    mutable psys::rt::Stats stats;
    // Fills the spelled types from the system's module.
    void describe();
};

namespace psys::capi {

// The options a C host gave (or the defaults where null), checked: the backend's name and
// maths are checked where the backend is made.
struct Options {
    std::string backend = "llvm", math = "fast";
    rt::SystemOptions system;
    bool optimize = true;
    std::optional<std::string> jitCache;   // psys_options.jit_cache (unset: NULL)
    std::vector<std::string> libraryPath;  // psys_options.library_path, split at ':'
};
psys_error* readOptions(const char* function, const psys_options* given, Options& out);

}  // namespace psys::capi
