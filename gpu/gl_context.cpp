#include "gpu/gl_context.h"
#include "gpu/gl_debug.h"

#include "codegen_glsl/glsl_shaders.h"

#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <algorithm>

#include <fmt/format.h>
#include <stdexcept>

namespace psys::gpu {

std::unique_ptr<HeadlessContext> HeadlessContext::open(std::string& error, const HeadlessContext* share) {
    // eglGetPlatformDisplay (without EXT) aborts in libepoxy before a display exists, and
    // so does the EXT entry point where no EGL offers it (no vendor library at all).
    if (!epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_EXT_platform_base") ||
        !epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_MESA_platform_surfaceless")) {
        error = "EGL has no surfaceless platform (EGL_MESA_platform_surfaceless): no EGL driver is installed, "
                "or it cannot run without a window system";
        return nullptr;
    }
    EGLDisplay display = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    EGLint major = 0, minor = 0;
    if (display == EGL_NO_DISPLAY || !eglInitialize(display, &major, &minor)) {
        error = fmt::format("no EGL surfaceless display (EGL error 0x{:04x}; Mesa's EGL, or a GPU driver's, is needed)",
                            eglGetError());
        return nullptr;
    }
    eglBindAPI(EGL_OPENGL_API);
    EGLint configAttributes[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLConfig config = nullptr;
    EGLint configs = 0;
    eglChooseConfig(display, configAttributes, &config, 1, &configs);
    EGLint contextAttributes[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                                  EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                  EGL_CONTEXT_OPENGL_DEBUG, debugOutputRequested() ? EGL_TRUE : EGL_FALSE, EGL_NONE};
    EGLContext context = eglCreateContext(display, configs ? config : EGL_NO_CONFIG_KHR,
                                          share ? static_cast<EGLContext>(share->context_) : EGL_NO_CONTEXT, contextAttributes);
    if (context == EGL_NO_CONTEXT) {
        error = fmt::format("cannot make an OpenGL 4.5 core context on the EGL surfaceless display (EGL error 0x{:04x})",
                            eglGetError());
        return nullptr;
    }
    std::unique_ptr<HeadlessContext> c(new HeadlessContext);
    c->display_ = display;
    c->context_ = context;
    if (share) return c;  // (made current by the thread that uses it)
    if (!c->makeCurrent()) {
        error = "cannot make the EGL surfaceless context current";
        return nullptr;
    }
    return c;
}

HeadlessContext::~HeadlessContext() {
    if (!context_) return;
    if (eglGetCurrentContext() == context_) eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display_, context_);
    // No eglTerminate: the display is shared by every context of the process (and
    // terminating it unloads the driver, whose allocations then show as leaks of an
    // unknown module under LeakSanitizer).
}

bool HeadlessContext::makeCurrent() {
    return eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_) == EGL_TRUE;
}

void HeadlessContext::release() { eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT); }

bool contextCurrent() { return eglGetCurrentContext() != EGL_NO_CONTEXT; }

namespace {
thread_local int sharedScopes = 0;
}

SharedContextScope::SharedContextScope() { ++sharedScopes; }
SharedContextScope::~SharedContextScope() { --sharedScopes; }
bool sharedContextCurrent() { return sharedScopes > 0; }

void checkAllocation(const char* what, size_t bytes) {
    bool outOfMemory = false;
    for (GLenum error = glGetError(); error != GL_NO_ERROR; error = glGetError()) outOfMemory |= error == GL_OUT_OF_MEMORY;
    if (outOfMemory)
        throw std::runtime_error("the GPU has no room for " + std::string(what) + " (" +
                                 std::to_string(bytes >> 20) + " MiB)");
}

void dispatchInvocations(size_t invocations, unsigned groupSize) {
    size_t groups = (invocations + groupSize - 1) / groupSize;
    if (groups == 0) return;
    size_t x = std::min<size_t>(groups, codegen_glsl::kMaxGroupsX);
    size_t y = (groups + x - 1) / x;
    glDispatchCompute(static_cast<GLuint>(x), static_cast<GLuint>(y), 1);
}

void bindParams(unsigned& buffer, std::initializer_list<uint32_t> values) {
    uint32_t words[12] = {};
    if (values.size() > 12) throw std::logic_error("a utility shader takes at most 12 parameters");
    std::copy(values.begin(), values.end(), words);
    if (!buffer) glCreateBuffers(1, &buffer);
    glNamedBufferData(buffer, sizeof words, words, GL_STREAM_DRAW);  // a new store: no dispatch in flight sees it
    glBindBufferBase(GL_UNIFORM_BUFFER, 1, buffer);
}

void sendThrough(unsigned& staging, unsigned target, size_t offset, size_t bytes, const void* data) {
    if (bytes == 0) return;
    if (!staging) glCreateBuffers(1, &staging);
    glNamedBufferData(staging, static_cast<GLsizeiptr>(bytes), data, GL_STREAM_COPY);  // a new store
    glCopyNamedBufferSubData(staging, target, 0, static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes));
}

std::string rendererName() {
    auto text = [](GLenum e) {
        const auto* s = reinterpret_cast<const char*>(glGetString(e));
        return std::string(s ? s : "?");
    };
    return text(GL_RENDERER) + ", OpenGL " + text(GL_VERSION);
}

}  // namespace psys::gpu
