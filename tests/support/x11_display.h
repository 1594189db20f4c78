#pragma once
// What the windowed tests need from X: a private Xvfb server, finding a
// window by its title, reading a window's pixels as the server holds them
// (what a person sees), mouse input, and asking a window to close as a
// window manager would. Xlib stays in the .cpp: its macros (None, Bool,
// Status) break C++ headers.
#include <sys/types.h>

#include <cstdint>
#include <string>
#include <vector>

#include "emoface/render/image.h"

struct _XDisplay;  // Xlib's Display

namespace emoface::testing {

// An Xvfb server on a display number it picks itself (-displayfd), so tests
// running side by side never collide. Stopped by the destructor.
class VirtualDisplay {
public:
    // Empty name() when Xvfb cannot be found or started; why() says which.
    VirtualDisplay(int width, int height);
    ~VirtualDisplay();
    VirtualDisplay(const VirtualDisplay&) = delete;
    VirtualDisplay& operator=(const VirtualDisplay&) = delete;

    const std::string& name() const { return name_; }  // ":93"
    const std::string& why() const { return why_; }

private:
    pid_t pid_ = -1;
    std::string name_, why_;
};

struct WindowShot {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgb;  // top row first
    std::string title;

    // The pixels as an opaque image (for render::diff_images).
    render::ImageRGBA8 image() const;
};

// The one grab: reads window `window` (an X window id) through an open
// connection, after XSync so that what was drawn has arrived. False when the
// pixels cannot be read. (GLFW: glfwGetX11Display(), glfwGetX11Window().)
bool grab_window(_XDisplay* connection, unsigned long window, WindowShot& shot);

// Waits up to `seconds` for a top-level window whose title starts with
// `title_prefix` and does not contain `not_containing` (when given), then
// reads its pixels. False on time-out or when the pixels cannot be read.
bool grab_window(const std::string& display, const std::string& title_prefix,
                 const std::string& not_containing, double seconds, WindowShot& shot);

// Mouse input as a person gives it, without the XTest extension: the
// pointer is warped (real motion events, and XQueryPointer sees it) and the
// button is pressed and released through synthetic events to the window.
// Drags button 1 (left), 2 (middle) or 3 (right) from (x0, y0) to (x1, y1)
// (window pixels) in `steps` moves, `pause_ms` apart so the program under
// test sees each. False when there is no such window.
bool drag(const std::string& display, const std::string& title_prefix, int button, int x0, int y0, int x1,
          int y1, int steps, int pause_ms);
// `notches` turns of the wheel at (x, y); positive turns away from the user
// (X buttons 4, or 5 for negative).
bool scroll(const std::string& display, const std::string& title_prefix, int x, int y, int notches,
            int pause_ms);

// Sends WM_DELETE_WINDOW to the first window titled `title_prefix`... (the
// close button of a window manager). False when there is no such window.
bool request_close(const std::string& display, const std::string& title_prefix);

}  // namespace emoface::testing
