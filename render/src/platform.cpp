#include "emoface/render/platform.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>

#include <fmt/format.h>

#include "gl_util.h"

namespace emoface::render {

using detail::check_gl;

namespace {
thread_local Platform* t_current = nullptr;
}

Platform::~Platform() = default;

void Platform::make_current() {
    if (t_current != this && t_current) t_current->unbind_context();
    bind_context();
    t_current = this;
}

void Platform::release_current() noexcept {
    if (t_current) t_current->unbind_context();
    t_current = nullptr;
}

void Platform::mark_current() noexcept { t_current = this; }

void Platform::forget_current() noexcept {
    if (t_current == this) t_current = nullptr;
}

bool Platform::is_software() const {
    return description_.find("llvmpipe") != std::string::npos ||
           description_.find("softpipe") != std::string::npos ||
           description_.find("swrast") != std::string::npos;
}

void Platform::init_gl(int width, int height, int samples, const std::string& platform_name) {
    const int version = epoxy_gl_version();
    if (epoxy_is_desktop_gl() == 0 || version < 33)
        fail<EnvironmentError>("render: {}: need desktop OpenGL 3.3 core, got version {}.{}",
                               platform_name, version / 10, version % 10);
    const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    const auto* gl_version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
    description_ = fmt::format("{}: {}, OpenGL {}", platform_name, renderer ? renderer : "?",
                               gl_version ? gl_version : "?");
    GLint max_samples = 1;
    glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
    samples_ = std::clamp(samples, 1, std::max(1, int(max_samples)));
    resize_targets(width, height);
}

void Platform::resize_targets(int width, int height) {
    if (width <= 0 || height <= 0 || width > 16384 || height > 16384)
        fail("render: framebuffer size must be in 1..16384, got {}x{}", width, height);
    destroy_gl();
    width_ = width;
    height_ = height;

    glGenFramebuffers(1, &draw_fbo_);
    glGenRenderbuffers(1, &draw_color_);
    glGenRenderbuffers(1, &draw_depth_);
    glBindRenderbuffer(GL_RENDERBUFFER, draw_color_);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples_ > 1 ? samples_ : 0, GL_RGBA8,
                                     width, height);
    glBindRenderbuffer(GL_RENDERBUFFER, draw_depth_);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples_ > 1 ? samples_ : 0,
                                     GL_DEPTH_COMPONENT24, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, draw_fbo_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, draw_color_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, draw_depth_);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        fail<EnvironmentError>("render: the {}x{} framebuffer with {} samples is incomplete",
                               width, height, samples_);

    glGenFramebuffers(1, &resolve_fbo_);
    glGenRenderbuffers(1, &resolve_color_);
    glBindRenderbuffer(GL_RENDERBUFFER, resolve_color_);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, resolve_fbo_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                              resolve_color_);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        fail<EnvironmentError>("render: the {}x{} resolve framebuffer is incomplete", width,
                               height);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    check_gl("creating the framebuffers");
}

void Platform::destroy_gl() {
    if (draw_fbo_) glDeleteFramebuffers(1, &draw_fbo_);
    if (resolve_fbo_) glDeleteFramebuffers(1, &resolve_fbo_);
    const GLuint rbs[3] = {draw_color_, draw_depth_, resolve_color_};
    if (draw_color_ || draw_depth_ || resolve_color_) glDeleteRenderbuffers(3, rbs);
    draw_fbo_ = resolve_fbo_ = draw_color_ = draw_depth_ = resolve_color_ = 0;
}

void Platform::close_gl() {
    make_current();
    destroy_gl();
    unbind_context();
    forget_current();
}

void Platform::begin_frame() {
    glBindFramebuffer(GL_FRAMEBUFFER, draw_fbo_);
    glViewport(0, 0, width_, height_);
}

void Platform::end_frame() {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, draw_fbo_);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_fbo_);
    glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT,
                      GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    // The one error check of a frame (the renderer's per-frame calls skip
    // theirs): whatever failed since the last check is reported here.
    check_gl("drawing or resolving the frame");
}

void Platform::read_rgba(ImageRGBA8& out) const {
    if (out.width != width_ || out.height != height_) out = ImageRGBA8(width_, height_);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, resolve_fbo_);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, out.pixels.data());
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    check_gl("reading the frame back");
    // GL's first row is the bottom one.
    const std::size_t row = out.row_bytes();
    std::vector<std::uint8_t> tmp(row);
    for (int y = 0; y < height_ / 2; ++y) {
        std::uint8_t* a = out.pixels.data() + std::size_t(y) * row;
        std::uint8_t* b = out.pixels.data() + std::size_t(height_ - 1 - y) * row;
        std::memcpy(tmp.data(), a, row);
        std::memcpy(a, b, row);
        std::memcpy(b, tmp.data(), row);
    }
}

ImageRGBA8 Platform::read_rgba() const {
    ImageRGBA8 out;
    read_rgba(out);
    return out;
}

}  // namespace emoface::render
