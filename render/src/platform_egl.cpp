// Headless platform: an EGL context with no surface (EGL_KHR_surfaceless_context);
// everything is drawn into the base class's framebuffers.
#include <algorithm>
#include <cstring>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include <epoxy/egl.h>
#include <fmt/format.h>

#include "emoface/render/platform.h"
#include "gl_util.h"

#ifndef EGL_PLATFORM_SURFACELESS_MESA
#define EGL_PLATFORM_SURFACELESS_MESA 0x31DD
#endif
#ifndef EGL_CUDA_DEVICE_NV
#define EGL_CUDA_DEVICE_NV 0x323A
#endif

namespace emoface::render {
namespace {

bool has_word(const char* list, const char* word) {
    if (!list) return false;
    const std::size_t n = std::strlen(word);
    for (const char* p = list; (p = std::strstr(p, word)) != nullptr; p += n) {
        const bool starts = p == list || p[-1] == ' ';
        const bool ends = p[n] == '\0' || p[n] == ' ';
        if (starts && ends) return true;
    }
    return false;
}

// EGL displays are not reference counted: eglTerminate ends every context
// on the display. Several headless platforms (tests) share a display, so the
// last one out terminates it.
std::mutex g_display_mutex;
std::map<EGLDisplay, int> g_display_users;

void retain_display(EGLDisplay d) {
    std::lock_guard<std::mutex> lock(g_display_mutex);
    ++g_display_users[d];
}
void release_display(EGLDisplay d) {
    std::lock_guard<std::mutex> lock(g_display_mutex);
    if (--g_display_users[d] == 0) {
        g_display_users.erase(d);
        eglTerminate(d);
    }
}

struct Candidate {
    EGLDisplay display;
    std::string name;
};

// Displays on GPUs exposed through EGL_EXT_device_enumeration, skipping
// Mesa's software device (surfaceless covers that), the requested CUDA device
// first.
std::vector<Candidate> device_displays(int cuda_device, std::string& notes) {
    std::vector<Candidate> out;
    const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!has_word(client, "EGL_EXT_device_enumeration") &&
        !has_word(client, "EGL_EXT_device_base")) {
        notes += " no EGL_EXT_device_enumeration;";
        return out;
    }
    if (!has_word(client, "EGL_EXT_platform_device")) {
        notes += " no EGL_EXT_platform_device;";
        return out;
    }
    EGLint count = 0;
    if (!eglQueryDevicesEXT(0, nullptr, &count) || count <= 0) {
        notes += " no EGL devices;";
        return out;
    }
    std::vector<EGLDeviceEXT> devices(static_cast<std::size_t>(count));
    eglQueryDevicesEXT(count, devices.data(), &count);
    std::vector<std::pair<int, Candidate>> ranked;
    for (EGLint i = 0; i < count; ++i) {
        const char* ext = eglQueryDeviceStringEXT(devices[i], EGL_EXTENSIONS);
        if (has_word(ext, "EGL_MESA_device_software")) continue;
        int rank = 1;
        if (cuda_device >= 0 && has_word(ext, "EGL_NV_device_cuda")) {
            EGLAttrib cuda = -1;
            if (eglQueryDeviceAttribEXT(devices[i], EGL_CUDA_DEVICE_NV, &cuda))
                rank = cuda == cuda_device ? 0 : 2;
        }
        EGLDisplay d = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
        if (d == EGL_NO_DISPLAY) continue;
        ranked.push_back({rank, Candidate{d, fmt::format("EGL device {}", i)}});
    }
    std::stable_sort(ranked.begin(), ranked.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    for (auto& r : ranked) out.push_back(r.second);
    if (out.empty()) notes += " only software EGL devices;";
    return out;
}

// Makes a GL 3.3 core context on an initialised display; EGL_NO_CONTEXT on failure.
EGLContext create_context(EGLDisplay d, std::string& notes) {
    if (!eglBindAPI(EGL_OPENGL_API)) {
        notes += " eglBindAPI(EGL_OPENGL_API) failed;";
        return EGL_NO_CONTEXT;
    }
    const EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLConfig config = nullptr;
    EGLint n = 0;
    const bool no_config = has_word(eglQueryString(d, EGL_EXTENSIONS), "EGL_KHR_no_config_context");
    if (!eglChooseConfig(d, config_attribs, &config, 1, &n) || n < 1) {
        if (!no_config) {
            notes += " no EGL config renders OpenGL;";
            return EGL_NO_CONTEXT;
        }
        config = nullptr;  // EGL_NO_CONFIG_KHR
    }
    const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 3,
                                      EGL_CONTEXT_MINOR_VERSION, 3,
                                      EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                      EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                      EGL_NONE};
    EGLContext ctx = eglCreateContext(d, config, EGL_NO_CONTEXT, context_attribs);
    if (ctx == EGL_NO_CONTEXT) {
        notes += fmt::format(" eglCreateContext(3.3 core) failed (0x{:x});", eglGetError());
        return EGL_NO_CONTEXT;
    }
    if (!eglMakeCurrent(d, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) {
        notes += fmt::format(" eglMakeCurrent without a surface failed (0x{:x});", eglGetError());
        eglDestroyContext(d, ctx);
        return EGL_NO_CONTEXT;
    }
    return ctx;
}

}  // namespace

HeadlessPlatform::HeadlessPlatform(const PlatformOptions& options) {
    using Egl = PlatformOptions::Egl;
    std::string notes;
    std::vector<Candidate> candidates;
    if (options.egl != Egl::Surfaceless) candidates = device_displays(options.cuda_device, notes);
    if (options.egl != Egl::Device) {
        const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
        if (has_word(client, "EGL_MESA_platform_surfaceless")) {
            EGLDisplay d =
                eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
            if (d != EGL_NO_DISPLAY) candidates.push_back({d, "EGL surfaceless"});
        } else {
            notes += " no EGL_MESA_platform_surfaceless;";
        }
    }
    release_current();
    for (const Candidate& c : candidates) {
        EGLint major = 0, minor = 0;
        if (!eglInitialize(c.display, &major, &minor)) {
            notes += fmt::format(" {}: eglInitialize failed (0x{:x});", c.name, eglGetError());
            continue;
        }
        retain_display(c.display);
        EGLContext ctx = create_context(c.display, notes);
        if (ctx == EGL_NO_CONTEXT) {
            release_display(c.display);
            continue;
        }
        display_ = c.display;
        context_ = ctx;
        mark_current();
        try {
            init_gl(options.width, options.height, options.samples, c.name);
        } catch (...) {
            forget_current();
            eglMakeCurrent(c.display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
            eglDestroyContext(c.display, ctx);
            release_display(c.display);
            throw;
        }
        return;
    }
    fail<EnvironmentError>("render: no headless OpenGL 3.3 core context through EGL:{}",
                           notes.empty() ? " no EGL platform found" : notes);
}

HeadlessPlatform::~HeadlessPlatform() {
    if (!context_) return;
    close_gl();
    eglDestroyContext(display_, context_);
    release_display(display_);
}

void HeadlessPlatform::bind_context() {
    if (eglGetCurrentContext() == context_) return;
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
        fail<EnvironmentError>("render: eglMakeCurrent failed (0x{:x})", eglGetError());
}

void HeadlessPlatform::unbind_context() noexcept {
    if (eglGetCurrentContext() == context_)
        eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
}

}  // namespace emoface::render
