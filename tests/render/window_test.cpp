// The GLFW window platform: opens where a display exists (CI runs this test
// under xvfb-run), draws the same pixels as the headless platform, and
// presents them to the window. Skips when there is no display.
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
#include "x11_screenshot.h"

namespace {

using namespace emoface::render;
using emoface::expression::TriMesh;

TriMesh tilted_quad() {
    TriMesh m;
    m.request_vertex_normals();
    m.request_vertex_texcoords2D();
    const float xy[4][2] = {{-0.8f, -0.6f}, {0.7f, -0.8f}, {0.8f, 0.7f}, {-0.6f, 0.8f}};
    TriMesh::VertexHandle v[4];
    for (int i = 0; i < 4; ++i) {
        v[i] = m.add_vertex({xy[i][0], xy[i][1], 0.1f * float(i)});
        m.set_texcoord2D(v[i], {(xy[i][0] + 1) / 2, (1 - xy[i][1]) / 2});
    }
    m.add_face(v[0], v[1], v[2]);
    m.add_face(v[0], v[2], v[3]);
    m.request_face_normals();
    m.update_normals();
    return m;
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
    std::vector<std::uint8_t> shot;
    ASSERT_TRUE(emoface::render::testing::grab_window_rgb(window->window(), window->width(),
                                                          window->height(), shot));
    int same = 0;
    for (int y = 0; y < window->height(); ++y)
        for (int x = 0; x < window->width(); ++x) {
            const std::uint8_t* s = &shot[(std::size_t(y) * window->width() + x) * 3];
            const std::uint8_t* f = in_window.at(x, y);
            same += std::abs(s[0] - f[0]) <= 1 && std::abs(s[1] - f[1]) <= 1 &&
                    std::abs(s[2] - f[2]) <= 1;
        }
    EXPECT_GT(same, window->width() * window->height() * 99 / 100)
        << "the window shows the rendered frame";
    window->poll_events();

    // The headless platform draws the same pixels (same GL underneath here).
    HeadlessPlatform headless(o);
    const ImageRGBA8 offscreen = draw_on(headless);
    if (headless.is_software() == window->is_software()) {
        int differing = 0;
        for (std::size_t i = 0; i < offscreen.pixels.size(); ++i)
            differing += std::abs(int(offscreen.pixels[i]) - int(in_window.pixels[i])) > 2;
        EXPECT_EQ(differing, 0);
    }
    // The quad is there and lit: the centre is neither background nor black.
    const std::uint8_t* centre = in_window.at(48, 32);
    EXPECT_GT(centre[0], 100);
    EXPECT_GT(centre[0], centre[2]);
}

}  // namespace
