#include "surface.h"

#include <algorithm>

#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <GLFW/glfw3.h>

namespace psys::viewer {

std::vector<uint8_t> Surface::pixels() {
    int w = width(), h = height();
    std::vector<uint8_t> rows(static_cast<size_t>(w) * static_cast<size_t>(h) * 4);
    bind();
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, rows.data());
    // GL's first row is the bottom one.
    std::vector<uint8_t> out(rows.size());
    size_t stride = static_cast<size_t>(w) * 4;
    for (int y = 0; y < h; ++y)
        std::copy_n(rows.data() + static_cast<size_t>(h - 1 - y) * stride, stride, out.data() + static_cast<size_t>(y) * stride);
    return out;
}

std::string Surface::renderer() const {
    auto text = [](GLenum e) {
        const auto* s = reinterpret_cast<const char*>(glGetString(e));
        return std::string(s ? s : "?");
    };
    return text(GL_RENDERER) + ", OpenGL " + text(GL_VERSION);
}

namespace {

// An EGL surfaceless context drawing into a framebuffer object.
class Offscreen : public Surface {
public:
    ~Offscreen() override {
        if (display_ == EGL_NO_DISPLAY) return;
        if (context_ != EGL_NO_CONTEXT) {
            glDeleteFramebuffers(1, &framebuffer_);
            glDeleteRenderbuffers(2, renderbuffers_);
            eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
            eglDestroyContext(display_, context_);
        }
        // No eglTerminate: the display is shared by every context of the process (and
        // terminating it unloads the driver, whose allocations then show as leaks of an
        // unknown module under LeakSanitizer).
    }

    bool open(int width, int height, std::string& error) {
        width_ = width;
        height_ = height;
        // eglGetPlatformDisplay (without EXT) aborts in libepoxy before a display exists.
        display_ = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
        EGLint major = 0, minor = 0;
        if (display_ == EGL_NO_DISPLAY || !eglInitialize(display_, &major, &minor)) {
            error = "no EGL surfaceless display (Mesa's EGL is needed for --headless)";
            return false;
        }
        eglBindAPI(EGL_OPENGL_API);
        EGLint configAttributes[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
        EGLConfig config = nullptr;
        EGLint configs = 0;
        eglChooseConfig(display_, configAttributes, &config, 1, &configs);
        EGLint contextAttributes[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                                      EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
        context_ = eglCreateContext(display_, configs ? config : EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, contextAttributes);
        if (context_ == EGL_NO_CONTEXT || !eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
            error = "cannot make an OpenGL 4.5 core context on the EGL surfaceless display";
            return false;
        }
        glGenRenderbuffers(2, renderbuffers_);
        glBindRenderbuffer(GL_RENDERBUFFER, renderbuffers_[0]);
        glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
        glBindRenderbuffer(GL_RENDERBUFFER, renderbuffers_[1]);
        glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
        glGenFramebuffers(1, &framebuffer_);
        glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, renderbuffers_[0]);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, renderbuffers_[1]);
        if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
            error = "the offscreen framebuffer is incomplete";
            return false;
        }
        return true;
    }

    int width() const override { return width_; }
    int height() const override { return height_; }
    void bind() override {
        glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
        glViewport(0, 0, width_, height_);
    }
    void present() override { glFinish(); }

private:
    EGLDisplay display_ = EGL_NO_DISPLAY;
    EGLContext context_ = EGL_NO_CONTEXT;
    GLuint framebuffer_ = 0, renderbuffers_[2] = {0, 0};
    int width_ = 0, height_ = 0;
};

class Window : public Surface {
public:
    ~Window() override {
        if (window_) glfwDestroyWindow(window_);
        glfwTerminate();
    }

    bool open(int width, int height, const std::string& title, std::string& error) {
        if (!glfwInit()) {
            error = "no display for a window (set DISPLAY, or use --headless)";
            return false;
        }
        glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
        glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
        glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
        glfwWindowHint(GLFW_CONTEXT_CREATION_API, GLFW_EGL_CONTEXT_API);
        window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
        if (!window_) {  // no EGL for this display: the native context API
            glfwWindowHint(GLFW_CONTEXT_CREATION_API, GLFW_NATIVE_CONTEXT_API);
            window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
        }
        if (!window_) {
            error = "cannot open an OpenGL 4.5 core window";
            return false;
        }
        glfwMakeContextCurrent(window_);
        glfwSwapInterval(1);
        return true;
    }

    int width() const override {
        int w, h;
        glfwGetFramebufferSize(window_, &w, &h);
        return w;
    }
    int height() const override {
        int w, h;
        glfwGetFramebufferSize(window_, &w, &h);
        return h;
    }
    void bind() override {
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glViewport(0, 0, width(), height());
    }
    void present() override { glfwSwapBuffers(window_); }
    bool closed() const override { return glfwWindowShouldClose(window_); }
    GLFWwindow* window() const override { return window_; }

private:
    GLFWwindow* window_ = nullptr;
};

}  // namespace

std::unique_ptr<Surface> openOffscreen(int width, int height, std::string& error) {
    auto s = std::make_unique<Offscreen>();
    if (!s->open(width, height, error)) return nullptr;
    return s;
}

std::unique_ptr<Surface> openWindow(int width, int height, const std::string& title, std::string& error) {
    auto s = std::make_unique<Window>();
    if (!s->open(width, height, title, error)) return nullptr;
    return s;
}

}  // namespace psys::viewer
