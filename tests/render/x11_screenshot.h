#pragma once
// A window's pixels as the X server holds them (what a person sees). In its
// own file because Xlib's macros (None, Bool, Status) break C++ headers.
#include <cstdint>
#include <vector>

struct GLFWwindow;

namespace emoface::render::testing {

// RGB bytes, top row first; false when the pixels cannot be read.
bool grab_window_rgb(GLFWwindow* window, int width, int height, std::vector<std::uint8_t>& rgb);

}  // namespace emoface::render::testing
