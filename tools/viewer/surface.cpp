#include "surface.h"

#include <algorithm>

#include <epoxy/gl.h>

#include <GLFW/glfw3.h>

#include "gpu/gl_context.h"

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

std::string Surface::renderer() const { return gpu::rendererName(); }

namespace {

class HeadlessWorker : public WorkerContext {
public:
    explicit HeadlessWorker(std::unique_ptr<gpu::HeadlessContext> context) : context_(std::move(context)) {}
    bool makeCurrent() override { return context_->makeCurrent(); }
    void release() override { context_->release(); }

private:
    std::unique_ptr<gpu::HeadlessContext> context_;
};

// A hidden window of GLFW's whose context shares the visible one's objects.
class WindowWorker : public WorkerContext {
public:
    explicit WindowWorker(GLFWwindow* window) : window_(window) {}
    ~WindowWorker() override { glfwDestroyWindow(window_); }
    bool makeCurrent() override {
        glfwMakeContextCurrent(window_);
        return glfwGetCurrentContext() == window_;
    }
    void release() override { glfwMakeContextCurrent(nullptr); }

private:
    GLFWwindow* window_;
};

// An EGL surfaceless context (gpu/gl_context.h) drawing into a framebuffer object.
class Offscreen : public Surface {
public:
    ~Offscreen() override {
        if (!context_) return;
        context_->makeCurrent();
        glDeleteFramebuffers(1, &framebuffer_);
        glDeleteRenderbuffers(2, renderbuffers_);
    }

    bool open(int width, int height, std::string& error) {
        width_ = width;
        height_ = height;
        context_ = gpu::HeadlessContext::open(error);
        if (!context_) return false;
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
    std::unique_ptr<WorkerContext> workerContext() override {
        std::string error;
        auto shared = gpu::HeadlessContext::open(error, context_.get());
        if (!shared) return nullptr;
        return std::make_unique<HeadlessWorker>(std::move(shared));
    }

private:
    std::unique_ptr<gpu::HeadlessContext> context_;
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
    // (the hints of the visible window's context still hold: the same version and API)
    std::unique_ptr<WorkerContext> workerContext() override {
        glfwWindowHint(GLFW_VISIBLE, GLFW_FALSE);
        GLFWwindow* hidden = glfwCreateWindow(1, 1, "psys-view worker", nullptr, window_);
        glfwWindowHint(GLFW_VISIBLE, GLFW_TRUE);
        glfwMakeContextCurrent(window_);
        if (!hidden) return nullptr;
        return std::make_unique<WindowWorker>(hidden);
    }

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
