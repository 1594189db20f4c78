#include "support/x11_display.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <X11/Xlib.h>
#include <X11/Xutil.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <thread>

namespace emoface::testing {

namespace {

bool on_path(const std::string& program) {
    const char* path = std::getenv("PATH");
    std::string dirs = path ? path : "/usr/bin:/bin";
    std::size_t start = 0;
    while (start <= dirs.size()) {
        const std::size_t end = dirs.find(':', start);
        const std::string dir = dirs.substr(start, end == std::string::npos ? std::string::npos : end - start);
        const std::string candidate = (dir.empty() ? "." : dir) + "/" + program;
        if (::access(candidate.c_str(), X_OK) == 0) return true;
        if (end == std::string::npos) break;
        start = end + 1;
    }
    return false;
}

int ignore_x_errors(Display*, XErrorEvent*) { return 0; }

struct Connection {
    explicit Connection(const std::string& name) : display(XOpenDisplay(name.c_str())) {
        if (display) XSetErrorHandler(ignore_x_errors);  // a window may vanish mid-query
    }
    ~Connection() {
        if (display) XCloseDisplay(display);
    }
    Display* display;
};

std::string title_of(Display* d, Window w) {
    char* name = nullptr;
    std::string title;
    if (XFetchName(d, w, &name) && name) title = name;
    if (name) XFree(name);
    return title;
}

// The first viewable top-level window (a child of the root, as there is no
// window manager) whose title matches.
Window find_window(Display* d, const std::string& prefix, const std::string& not_containing,
                   std::string* title) {
    Window root_return = 0, parent = 0, found = 0;
    Window* children = nullptr;
    unsigned count = 0;
    if (!XQueryTree(d, DefaultRootWindow(d), &root_return, &parent, &children, &count)) return 0;
    for (unsigned i = 0; i < count && !found; ++i) {
        const std::string t = title_of(d, children[i]);
        if (t.compare(0, prefix.size(), prefix) != 0) continue;
        if (!not_containing.empty() && t.find(not_containing) != std::string::npos) continue;
        XWindowAttributes a;
        if (XGetWindowAttributes(d, children[i], &a) && a.map_state == IsViewable) {
            found = children[i];
            if (title) *title = t;
        }
    }
    if (children) XFree(children);
    return found;
}

int shift_of(unsigned long mask) {
    int s = 0;
    while (mask && !(mask & 1)) {
        mask >>= 1;
        ++s;
    }
    return s;
}

}  // namespace

VirtualDisplay::VirtualDisplay(int width, int height) {
    if (!on_path("Xvfb")) {
        why_ = "Xvfb is not installed (package xvfb, listed in scripts/deps)";
        return;
    }
    int fds[2];
    if (::pipe(fds) != 0) {
        why_ = "pipe() failed";
        return;
    }
    const std::string fd = std::to_string(fds[1]);
    const std::string screen = std::to_string(width) + "x" + std::to_string(height) + "x24";
    pid_ = ::fork();
    if (pid_ == 0) {
        ::close(fds[0]);
        const int null = ::open("/dev/null", O_RDWR);
        if (null >= 0) {
            ::dup2(null, 0);
            ::dup2(null, 1);
            ::dup2(null, 2);
        }
        ::execlp("Xvfb", "Xvfb", "-displayfd", fd.c_str(), "-screen", "0", screen.c_str(), "-nolisten",
                 "tcp", static_cast<char*>(nullptr));
        ::_exit(127);
    }
    ::close(fds[1]);
    if (pid_ < 0) {
        ::close(fds[0]);
        why_ = "fork() failed";
        return;
    }
    // Xvfb writes its display number once it accepts connections.
    std::string number;
    pollfd p{fds[0], POLLIN, 0};
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (std::chrono::steady_clock::now() < deadline) {
        if (::poll(&p, 1, 200) > 0) {
            char c = 0;
            if (::read(fds[0], &c, 1) != 1) break;
            if (c == '\n') break;
            number += c;
        }
    }
    ::close(fds[0]);
    if (number.empty()) {
        why_ = "Xvfb did not start (no display number within 20 s)";
        ::kill(pid_, SIGTERM);
        ::waitpid(pid_, nullptr, 0);
        pid_ = -1;
        return;
    }
    name_ = ":" + number;
}

VirtualDisplay::~VirtualDisplay() {
    if (pid_ > 0) {
        ::kill(pid_, SIGTERM);
        ::waitpid(pid_, nullptr, 0);
    }
}

bool grab_window(const std::string& display, const std::string& title_prefix,
                 const std::string& not_containing, double seconds, WindowShot& shot) {
    Connection c(display);
    if (!c.display) return false;
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::milliseconds(long(seconds * 1000));
    Window w = 0;
    while (!(w = find_window(c.display, title_prefix, not_containing, &shot.title))) {
        if (std::chrono::steady_clock::now() > deadline) return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return grab_window(c.display, w, shot);
}

bool grab_window(Display* connection, unsigned long window, WindowShot& shot) {
    XSync(connection, False);
    XWindowAttributes a;
    if (!XGetWindowAttributes(connection, window, &a)) return false;
    XImage* image = XGetImage(connection, window, 0, 0, unsigned(a.width), unsigned(a.height), AllPlanes, ZPixmap);
    if (!image) return false;
    shot.width = a.width;
    shot.height = a.height;
    shot.rgb.resize(std::size_t(a.width) * std::size_t(a.height) * 3);
    const int rs = shift_of(image->red_mask), gs = shift_of(image->green_mask), bs = shift_of(image->blue_mask);
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x) {
            const unsigned long px = XGetPixel(image, x, y);
            std::uint8_t* o = &shot.rgb[(std::size_t(y) * std::size_t(a.width) + std::size_t(x)) * 3];
            o[0] = std::uint8_t((px & image->red_mask) >> rs);
            o[1] = std::uint8_t((px & image->green_mask) >> gs);
            o[2] = std::uint8_t((px & image->blue_mask) >> bs);
        }
    XDestroyImage(image);
    return true;
}

render::ImageRGBA8 WindowShot::image() const {
    render::ImageRGBA8 out(width, height);
    for (std::size_t i = 0; i < std::size_t(width) * std::size_t(height); ++i) {
        std::copy_n(&rgb[3 * i], 3, &out.pixels[4 * i]);
        out.pixels[4 * i + 3] = 255;
    }
    return out;
}

namespace {

void send_button(Display* d, Window w, int type, unsigned button, int x, int y) {
    XEvent e;
    std::memset(&e, 0, sizeof e);
    e.xbutton.type = type;
    e.xbutton.display = d;
    e.xbutton.window = w;
    e.xbutton.root = DefaultRootWindow(d);
    e.xbutton.time = CurrentTime;
    e.xbutton.x = x;
    e.xbutton.y = y;
    Window child = 0;
    XTranslateCoordinates(d, w, e.xbutton.root, x, y, &e.xbutton.x_root, &e.xbutton.y_root, &child);
    e.xbutton.button = button;
    e.xbutton.same_screen = True;
    if (type == ButtonRelease) e.xbutton.state = Button1Mask << (button - 1);
    XSendEvent(d, w, True, type == ButtonPress ? ButtonPressMask : ButtonReleaseMask, &e);
    XFlush(d);
}

void move_pointer(Display* d, Window w, int x, int y, int pause_ms) {
    XWarpPointer(d, 0, w, 0, 0, 0, 0, x, y);
    XSync(d, False);
    std::this_thread::sleep_for(std::chrono::milliseconds(pause_ms));
}

}  // namespace

bool drag(const std::string& display, const std::string& title_prefix, int button, int x0, int y0, int x1, int y1,
          int steps, int pause_ms) {
    Connection c(display);
    if (!c.display) return false;
    const Window w = find_window(c.display, title_prefix, "", nullptr);
    if (!w) return false;
    move_pointer(c.display, w, x0, y0, pause_ms);
    send_button(c.display, w, ButtonPress, unsigned(button), x0, y0);
    std::this_thread::sleep_for(std::chrono::milliseconds(pause_ms));
    for (int i = 1; i <= steps; ++i)
        move_pointer(c.display, w, x0 + (x1 - x0) * i / steps, y0 + (y1 - y0) * i / steps, pause_ms);
    send_button(c.display, w, ButtonRelease, unsigned(button), x1, y1);
    std::this_thread::sleep_for(std::chrono::milliseconds(pause_ms));
    return true;
}

bool scroll(const std::string& display, const std::string& title_prefix, int x, int y, int notches, int pause_ms) {
    Connection c(display);
    if (!c.display) return false;
    const Window w = find_window(c.display, title_prefix, "", nullptr);
    if (!w) return false;
    move_pointer(c.display, w, x, y, pause_ms);
    const unsigned button = notches > 0 ? 4 : 5;
    for (int i = 0; i < std::abs(notches); ++i) {
        send_button(c.display, w, ButtonPress, button, x, y);
        send_button(c.display, w, ButtonRelease, button, x, y);
        std::this_thread::sleep_for(std::chrono::milliseconds(pause_ms));
    }
    return true;
}

bool request_close(const std::string& display, const std::string& title_prefix) {
    Connection c(display);
    if (!c.display) return false;
    const Window w = find_window(c.display, title_prefix, "", nullptr);
    if (!w) return false;
    XEvent e;
    std::memset(&e, 0, sizeof e);
    e.xclient.type = ClientMessage;
    e.xclient.window = w;
    e.xclient.message_type = XInternAtom(c.display, "WM_PROTOCOLS", False);
    e.xclient.format = 32;
    e.xclient.data.l[0] = long(XInternAtom(c.display, "WM_DELETE_WINDOW", False));
    e.xclient.data.l[1] = CurrentTime;
    XSendEvent(c.display, w, False, NoEventMask, &e);
    XFlush(c.display);
    return true;
}

}  // namespace emoface::testing
