// Window platform: a GLFW window with a GL 3.3 core context; frames are drawn
// into the base class's framebuffers and blitted to the window.
#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <mutex>
#include <string>

#include "emoface/render/platform.h"
#include "gl_util.h"

namespace emoface::render {
namespace {

std::mutex g_glfw_mutex;
int g_glfw_windows = 0;
std::string g_glfw_error;

void on_glfw_error(int code, const char* message) {
    g_glfw_error = fmt::format("{} (0x{:x})", message ? message : "?", code);
}

// glfwInit once for all windows; glfwTerminate with the last one.
void retain_glfw() {
    std::lock_guard<std::mutex> lock(g_glfw_mutex);
    if (g_glfw_windows == 0) {
        glfwSetErrorCallback(on_glfw_error);
        if (!glfwInit())
            fail<EnvironmentError>("render: cannot open a window (no display?): glfwInit: {}",
                                   g_glfw_error.empty() ? "failed" : g_glfw_error);
    }
    ++g_glfw_windows;
}
void release_glfw() {
    std::lock_guard<std::mutex> lock(g_glfw_mutex);
    if (--g_glfw_windows == 0) glfwTerminate();
}

}  // namespace

WindowPlatform::WindowPlatform(const PlatformOptions& options) {
    retain_glfw();
    glfwDefaultWindowHints();
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_VISIBLE, options.visible ? GLFW_TRUE : GLFW_FALSE);
    // The window only receives resolved frames: no depth or samples of its own.
    glfwWindowHint(GLFW_DEPTH_BITS, 0);
    glfwWindowHint(GLFW_SAMPLES, 0);
    window_ = glfwCreateWindow(options.width, options.height, options.title.c_str(), nullptr,
                               nullptr);
    if (!window_) {
        release_glfw();
        fail<EnvironmentError>("render: cannot create a {}x{} window with OpenGL 3.3 core: {}",
                               options.width, options.height,
                               g_glfw_error.empty() ? "glfwCreateWindow failed" : g_glfw_error);
    }
    release_current();
    glfwMakeContextCurrent(window_);
    mark_current();
    glfwSwapInterval(options.vsync ? 1 : 0);
    try {
        int fw = 0, fh = 0;
        glfwGetFramebufferSize(window_, &fw, &fh);
        init_gl(fw > 0 ? fw : options.width, fh > 0 ? fh : options.height, options.samples,
                "GLFW window");
    } catch (...) {
        forget_current();
        glfwMakeContextCurrent(nullptr);
        glfwDestroyWindow(window_);
        release_glfw();
        throw;
    }
}

WindowPlatform::~WindowPlatform() {
    if (!window_) return;
    close_gl();
    glfwDestroyWindow(window_);
    release_glfw();
}

void WindowPlatform::bind_context() {
    if (glfwGetCurrentContext() != window_) glfwMakeContextCurrent(window_);
}

void WindowPlatform::unbind_context() noexcept {
    if (glfwGetCurrentContext() == window_) glfwMakeContextCurrent(nullptr);
}

void WindowPlatform::end_frame() {
    Platform::end_frame();
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(window_, &fw, &fh);
    if (fw > 0 && fh > 0) {
        glBindFramebuffer(GL_READ_FRAMEBUFFER, resolve_framebuffer());
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
        glClearColor(0, 0, 0, 1);
        glClear(GL_COLOR_BUFFER_BIT);
        glBlitFramebuffer(0, 0, width(), height(), 0, 0, fw, fh, GL_COLOR_BUFFER_BIT, GL_LINEAR);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        detail::check_gl("presenting the frame");
    }
    glfwSwapBuffers(window_);
    // Follow the window's size from the next frame on (the caller reads
    // width()/height() for its projection).
    if (fw > 0 && fh > 0 && (fw != width() || fh != height())) resize_targets(fw, fh);
}

bool WindowPlatform::should_close() const { return glfwWindowShouldClose(window_) != 0; }

void WindowPlatform::poll_events() { glfwPollEvents(); }

}  // namespace emoface::render
