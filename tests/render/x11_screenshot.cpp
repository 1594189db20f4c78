#include "x11_screenshot.h"

#include <X11/Xlib.h>
#include <X11/Xutil.h>

// From glfw3native.h, whose X11 part also wants the Xrandr headers.
extern "C" Display* glfwGetX11Display(void);
extern "C" Window glfwGetX11Window(GLFWwindow* window);

namespace emoface::render::testing {

namespace {
int shift_of(unsigned long mask) {
    int s = 0;
    while (mask && !(mask & 1)) {
        mask >>= 1;
        ++s;
    }
    return s;
}
}  // namespace

bool grab_window_rgb(GLFWwindow* window, int width, int height, std::vector<std::uint8_t>& rgb) {
    Display* display = glfwGetX11Display();
    if (!display) return false;
    XSync(display, False);
    XImage* shot = XGetImage(display, glfwGetX11Window(window), 0, 0, unsigned(width),
                             unsigned(height), AllPlanes, ZPixmap);
    if (!shot) return false;
    rgb.resize(std::size_t(width) * height * 3);
    const int rs = shift_of(shot->red_mask), gs = shift_of(shot->green_mask),
              bs = shift_of(shot->blue_mask);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const unsigned long p = XGetPixel(shot, x, y);
            std::uint8_t* d = &rgb[(std::size_t(y) * width + x) * 3];
            d[0] = std::uint8_t((p & shot->red_mask) >> rs);
            d[1] = std::uint8_t((p & shot->green_mask) >> gs);
            d[2] = std::uint8_t((p & shot->blue_mask) >> bs);
        }
    XDestroyImage(shot);
    return true;
}

}  // namespace emoface::render::testing
