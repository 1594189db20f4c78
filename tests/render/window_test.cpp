// The GLFW window platform: opens where a display exists (CI runs this test
// under xvfb-run), draws the same pixels as the headless platform, and
// presents them to the window. Skips when there is no display.
#include <array>
#include <cstdlib>
#include <memory>

#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "emoface/common/error.h"
#include "emoface/render/platform.h"
#include "emoface/render/renderer.h"
#include "emoface/render/image_diff.h"
#include "quad_mesh.h"
#include "support/x11_display.h"

// From glfw3native.h, declared here: its X11 part pulls in Xlib (whose
// macros break C++ headers) and the Xrandr headers. An X Window is an XID.
extern "C" _XDisplay* glfwGetX11Display(void);
extern "C" unsigned long glfwGetX11Window(GLFWwindow* window);

namespace {

using namespace emoface::render;
using emoface::expression::TriMesh;

TriMesh tilted_quad() {
    const float xy[4][2] = {{-0.8f, -0.6f}, {0.7f, -0.8f}, {0.8f, 0.7f}, {-0.6f, 0.8f}};
    std::array<glm::vec3, 4> corners;
    std::array<glm::vec2, 4> uvs;
    for (int i = 0; i < 4; ++i) {
        corners[i] = {xy[i][0], xy[i][1], 0.1f * float(i)};
        uvs[i] = {(xy[i][0] + 1) / 2, (1 - xy[i][1]) / 2};
    }
    return emoface::render::testing::quad_mesh(corners, uvs);
}

ImageRGBA8 draw_on(Platform& platform) {
    Renderer renderer(platform);
    Material material;
    material.base_color = {0.8f, 0.5f, 0.3f};
    renderer.add_mesh(tilted_quad(), material);
    DrawOptions options;
    options.camera = Camera::look_at({0, 0, 3}, {0, 0, 0}, {0, 1, 0}, 45.0f,
                                     float(platform.width()) / float(platform.height()), 0.1f,
                                     10.0f);
    options.light.position = {0.3f, 0.4f, 1.0f, 0.0f};
    platform.begin_frame();
    renderer.draw(options, nullptr);
    platform.end_frame();
    return platform.read_rgba();
}

TEST(WindowPlatform, OpensDrawsAndPresents) {
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display) GTEST_SKIP() << "no DISPLAY: the window platform needs X (CI runs this under xvfb-run)";
    PlatformOptions o;
    o.width = 96;
    o.height = 64;
    o.vsync = false;
    std::unique_ptr<WindowPlatform> window;
    try {
        window = std::make_unique<WindowPlatform>(o);
    } catch (const emoface::EnvironmentError& e) {
        FAIL() << "DISPLAY=" << display << " is set but no window opens: " << e.what();
    }
    EXPECT_NE(window->description().find("GLFW window"), std::string::npos)
        << window->description();
    EXPECT_FALSE(window->should_close());
    draw_on(*window);
    window->poll_events();  // let the window be mapped before the frame that is checked
    const ImageRGBA8 in_window = draw_on(*window);
    glFinish();

    // What a person sees: the window's pixels as the X server holds them.
    glFinish();
    window->poll_events();
    emoface::testing::WindowShot shot;
    ASSERT_TRUE(emoface::testing::grab_window(glfwGetX11Display(), glfwGetX11Window(window->window()), shot));
    ImageDiffOptions within_one;
    within_one.pixel_tolerance = 1;
    EXPECT_LT(diff_images(shot.image(), in_window, within_one).failing_fraction(), 0.01)
        << "the window shows the rendered frame";
    window->poll_events();

    // The headless platform draws the same pixels (same GL underneath here).
    HeadlessPlatform headless(o);
    const ImageRGBA8 offscreen = draw_on(headless);
    if (headless.is_software() == window->is_software()) {
        ImageDiffOptions within_two;
        within_two.pixel_tolerance = 2;
        EXPECT_EQ(diff_images(offscreen, in_window, within_two).failing_pixels, 0u);
    }
    // The quad is there and lit: the centre is neither background nor black.
    const std::uint8_t* centre = in_window.at(48, 32);
    EXPECT_GT(centre[0], 100);
    EXPECT_GT(centre[0], centre[2]);
}

}  // namespace
