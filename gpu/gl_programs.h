// Compiling the GLSL backend's programs: a system of many object types has thousands
// (four or more shaders a type), and the GL's compile and link is most of its start-up.
//
// - In parallel where the driver can (GL_KHR_parallel_shader_compile /
//   GL_ARB_parallel_shader_compile): every program of a plan is begun — compiled and
//   linked, its status not asked — before any is finished, so the driver's threads work
//   on the rest meanwhile.
// - Kept on disk where the driver gives binaries (GL_ARB_get_program_binary, core since
//   4.1, where GL_NUM_PROGRAM_BINARY_FORMATS > 0): a program whose source was linked
//   before, by the same renderer and version, is loaded instead of compiled. In
//   PSYS_GL_CACHE (a directory; 0 turns it off), else $XDG_CACHE_HOME/psys/gl, else
//   ~/.cache/psys/gl. A binary the driver refuses (a newer driver) is compiled again.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

namespace psys::gpu {

// A linked program of one compute shader (the backend's own utility shaders: no cache);
// throws std::runtime_error with the GL's log, naming `what`, when the GL does not
// compile or link it (a fault of ours, not the user's).
unsigned computeProgram(const std::string& source, const std::string& what);

class ProgramCompiler {
public:
    // On the current context; `cache`: keep binaries on disk where the driver gives them.
    explicit ProgramCompiler(bool cache = true);
    // A program for `source`: loaded from the cache, or compiled and linked (not waited for).
    unsigned begin(const std::string& source);
    // Waits for it; throws std::runtime_error with the GL's log, naming `what`, where it
    // did not compile or link (a fault of ours, not the user's); keeps its binary.
    void finish(unsigned program, const std::string& source, const std::string& what);
    size_t loaded = 0, compiled = 0;  // programs so far, from the cache and compiled
    bool parallel = false;            // the driver compiles on threads of its own
    bool binaries = false;            // the driver gives program binaries (and a cache directory is set)

private:
    std::filesystem::path file(const std::string& source) const;
    std::string renderer_;
    std::filesystem::path directory_;
};

}  // namespace psys::gpu
