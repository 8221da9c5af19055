// Where the viewer draws: a window (GLFW; an OpenGL 4.5 core context through EGL where
// GLFW offers it, else GLX) or an offscreen framebuffer of an EGL surfaceless context, which
// needs no display at all (Mesa's llvmpipe renders it on the CPU).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

struct GLFWwindow;

namespace psys::viewer {

// A context sharing a surface's objects (programs, buffers), for another thread: the
// reloader's worker compiles a GLSL backend's programs in it while frames go on.
class WorkerContext {
public:
    virtual ~WorkerContext() = default;
    virtual bool makeCurrent() = 0;  // on the thread that uses it
    virtual void release() = 0;
};

class Surface {
public:
    virtual ~Surface() = default;
    virtual int width() const = 0;
    virtual int height() const = 0;
    // Binds the framebuffer frames are drawn into (and sets the viewport).
    virtual void bind() = 0;
    // Shows the frame (a window swaps; offscreen does nothing).
    virtual void present() = 0;
    virtual bool closed() const { return false; }
    virtual GLFWwindow* window() const { return nullptr; }
    // The last frame's pixels, RGBA8, top row first.
    std::vector<uint8_t> pixels();
    std::string renderer() const;  // "llvmpipe (LLVM 15.0.6, 256 bits)", …
    // Made on the surface's thread; null where the platform gives none.
    virtual std::unique_ptr<WorkerContext> workerContext() { return nullptr; }
};

// Null and `error` set when there is no way to open one.
std::unique_ptr<Surface> openOffscreen(int width, int height, std::string& error);
std::unique_ptr<Surface> openWindow(int width, int height, const std::string& title, std::string& error);

}  // namespace psys::viewer
