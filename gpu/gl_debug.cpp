#include "gpu/gl_debug.h"

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <mutex>

#include <epoxy/gl.h>

#include "core/log.h"

namespace psys::gpu {

namespace {

std::atomic<int> requested{-1};  // -1: not decided yet (the environment decides)
std::atomic<uint64_t> errors{0};
std::mutex lastMutex;
std::string last;

bool environment() {
    const char* v = std::getenv("PSYS_GL_DEBUG");
    return v && *v && std::strcmp(v, "0") != 0;
}

const char* typeName(GLenum type) {
    switch (type) {
        case GL_DEBUG_TYPE_ERROR: return "error";
        case GL_DEBUG_TYPE_UNDEFINED_BEHAVIOR: return "undefined behaviour";
        case GL_DEBUG_TYPE_DEPRECATED_BEHAVIOR: return "deprecated";
        case GL_DEBUG_TYPE_PERFORMANCE: return "performance";
        case GL_DEBUG_TYPE_PORTABILITY: return "portability";
        default: return "other";
    }
}

void GLAPIENTRY onMessage(GLenum, GLenum type, GLuint id, GLenum severity, GLsizei length, const GLchar* message,
                          const void*) {
    std::string text(message, length >= 0 ? static_cast<size_t>(length) : std::strlen(message));
    bool bad = type == GL_DEBUG_TYPE_ERROR || type == GL_DEBUG_TYPE_UNDEFINED_BEHAVIOR;
    if (bad) {
        ++errors;
        std::lock_guard<std::mutex> lock(lastMutex);
        last = std::string(typeName(type)) + " (id " + std::to_string(id) + "): " + text;
    }
    if (environment() && (bad || severity != GL_DEBUG_SEVERITY_NOTIFICATION))
        core::log(bad ? core::LogLevel::Error : core::LogLevel::Warning, "GL " + std::string(typeName(type)) + ": " + text);
}

}  // namespace

void requestDebugOutput(bool on) { requested = on ? 1 : 0; }

bool debugOutputRequested() {
    int r = requested.load();
    return r < 0 ? environment() : r != 0;
}

bool installDebugOutput() {
    if (epoxy_gl_version() < 43 && !epoxy_has_gl_extension("GL_KHR_debug")) return false;
    glEnable(GL_DEBUG_OUTPUT);
    glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
    glDebugMessageCallback(onMessage, nullptr);
    glDebugMessageControl(GL_DONT_CARE, GL_DONT_CARE, GL_DONT_CARE, 0, nullptr, GL_TRUE);
    return true;
}

uint64_t glErrorMessages() { return errors.load(); }

std::string lastGlErrorMessage() {
    std::lock_guard<std::mutex> lock(lastMutex);
    return last;
}

}  // namespace psys::gpu
