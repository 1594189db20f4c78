#pragma once
// Where the renderer's GL 3.3 core context comes from. One renderer, two
// platforms (in the way Filament's PlatformEGLHeadless is a small variant of
// its windowed platform): both draw into the same multisampled framebuffer,
// resolve it into a single-sample one, and read RGBA back from there; they
// differ only in how the context is made and where a finished frame goes.
//   WindowPlatform:   a GLFW window; end_frame() blits to it and swaps.
//   HeadlessPlatform: EGL with no surface at all: the NVIDIA EGL device when
//                     one is present, else Mesa's surfaceless platform
//                     (llvmpipe in CI); end_frame() only resolves.
// GL functions are loaded with libepoxy (GLEW fails under EGL).
#include <memory>
#include <string>

#include "emoface/render/image.h"

struct GLFWwindow;

namespace emoface::render {

struct PlatformOptions {
    int width = 512;
    int height = 512;
    int samples = 4;  // MSAA samples of the draw target (1 = none)
    // Headless only: which EGL platform to use. Auto tries the EGL device
    // platform (a real GPU) first, then Mesa surfaceless.
    enum class Egl { Auto, Device, Surfaceless } egl = Egl::Auto;
    // Headless only: the CUDA device the EGL device should be (so CUDA-GL
    // interop shares one GPU); -1 = any.
    int cuda_device = -1;
    // Window only.
    std::string title = "emoface";
    bool visible = true;
    bool vsync = true;
};

class Platform {
public:
    virtual ~Platform();
    Platform(const Platform&) = delete;
    Platform& operator=(const Platform&) = delete;

    int width() const { return width_; }
    int height() const { return height_; }
    int samples() const { return samples_; }
    // One line naming the platform and the GL renderer, e.g.
    // "EGL device: NVIDIA H100 80GB HBM3/PCIe/SSE2, OpenGL 4.6.0 NVIDIA 580.159.04".
    const std::string& description() const { return description_; }
    bool is_software() const;  // llvmpipe / softpipe / swrast

    // Makes this platform's context current on the calling thread, first
    // releasing another platform's (a GLX window's and an EGL context cannot
    // both be current: EGL answers EGL_BAD_ACCESS).
    void make_current();
    // Binds the multisampled draw framebuffer and sets the viewport to it.
    void begin_frame();
    // Resolves the draw framebuffer (and presents it, for a window).
    virtual void end_frame();
    // The last resolved frame, top row first. Waits for the GPU.
    ImageRGBA8 read_rgba() const;
    void read_rgba(ImageRGBA8& out) const;

    unsigned draw_framebuffer() const { return draw_fbo_; }
    unsigned resolve_framebuffer() const { return resolve_fbo_; }

protected:
    Platform() = default;
    // Context switching, implemented per platform; make_current() calls them.
    virtual void bind_context() = 0;
    virtual void unbind_context() noexcept = 0;
    // Releases whichever platform's context is current on this thread (before
    // a constructor makes its new context current).
    static void release_current() noexcept;
    // Records that this platform's context was made current directly.
    void mark_current() noexcept;
    // For destructors: forgets this platform if it is the current one.
    void forget_current() noexcept;
    // Called by subclasses once their context is current: loads GL through
    // epoxy, checks the version, creates the framebuffers.
    void init_gl(int width, int height, int samples, const std::string& platform_name);
    void resize_targets(int width, int height);
    void destroy_gl();
    // For destructors, before the context itself goes: deletes the
    // framebuffers in this platform's context, then leaves no context current.
    void close_gl();

private:
    int width_ = 0, height_ = 0, samples_ = 1;
    unsigned draw_fbo_ = 0, draw_color_ = 0, draw_depth_ = 0;
    unsigned resolve_fbo_ = 0, resolve_color_ = 0;
    std::string description_;
};

class WindowPlatform final : public Platform {
public:
    // Throws emoface::EnvironmentError when no display can be opened.
    explicit WindowPlatform(const PlatformOptions& options);
    ~WindowPlatform() override;
    // Resolves, blits to the window (letterboxed to its current size) and swaps.
    void end_frame() override;
    bool should_close() const;
    void poll_events();
    GLFWwindow* window() const { return window_; }

private:
    void bind_context() override;
    void unbind_context() noexcept override;

    GLFWwindow* window_ = nullptr;
};

class HeadlessPlatform final : public Platform {
public:
    // Throws emoface::EnvironmentError when no EGL platform gives a GL 3.3
    // core context.
    explicit HeadlessPlatform(const PlatformOptions& options);
    ~HeadlessPlatform() override;

private:
    void bind_context() override;
    void unbind_context() noexcept override;

    void* display_ = nullptr;  // EGLDisplay
    void* context_ = nullptr;  // EGLContext
};

}  // namespace emoface::render
