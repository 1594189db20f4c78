// The interactive viewer (apps/src/viewer.h):
//  - its arithmetic (the emotion sliders' sum rule, the orbit camera, the
//    light control) directly;
//  - `emoface view` end to end: without a display it exits 3 naming the fix,
//    on bad input it exits 2 before opening anything, and on a private Xvfb
//    server (started here, so CI needs no wrapper) it opens a real window,
//    renders, closes on its own after --quit-after frames or when asked
//    through WM_DELETE_WINDOW, and its --screenshot matches what the X server
//    shows in the window.
// Without Xvfb installed the windowed cases skip with a message.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "emoface/render/image_diff.h"
#include "emoface/render/image_io.h"
#include "emoface/render/renderer.h"
#include "viewer_controls.h"
#include "support/run_emoface.h"
#include "support/scratch_dir.h"
#include "support/x11_display.h"

namespace {

namespace fs = std::filesystem;
using emoface::apps::LightControl;
using emoface::apps::OrbitCamera;
using emoface::apps::set_emotion_slider;
using emoface::render::ImageRGBA8;

// --- the controls --------------------------------------------------------------

struct SliderCase {
    std::array<float, 6> before;
    int moved;
    float value;
    std::array<float, 6> after;
    bool scaled;
};

TEST(ViewerControls, EmotionSlidersNeverSumOverOne) {
    // joy, sadness, anger, fear, disgust, surprise
    const SliderCase cases[] = {
        {{0, 0, 0, 0, 0, 0}, 2, 0.7f, {0, 0, 0.7f, 0, 0, 0}, false},
        // 0.7 anger + 0.3 fear sums to exactly 1: nothing scaled.
        {{0, 0, 0.7f, 0, 0, 0}, 3, 0.3f, {0, 0, 0.7f, 0.3f, 0, 0}, false},
        // Raising fear to 0.5 leaves anger the 0.5 that is left.
        {{0, 0, 0.7f, 0.3f, 0, 0}, 3, 0.5f, {0, 0, 0.5f, 0.5f, 0, 0}, true},
        // The others shrink together, keeping their ratios.
        {{0.4f, 0.2f, 0, 0, 0, 0}, 5, 0.7f, {0.2f, 0.1f, 0, 0, 0, 0.7f}, true},
        // Full surprise leaves no room for anything else.
        {{0.2f, 0.2f, 0.2f, 0.2f, 0.2f, 0}, 5, 1.0f, {0, 0, 0, 0, 0, 1.0f}, true},
        // Lowering a slider never touches the others.
        {{0.5f, 0.5f, 0, 0, 0, 0}, 0, 0.1f, {0.1f, 0.5f, 0, 0, 0, 0}, false},
        // Values outside [0, 1] are clamped.
        {{0, 0.3f, 0, 0, 0, 0}, 0, -0.5f, {0, 0.3f, 0, 0, 0, 0}, false},
        {{0, 0.3f, 0, 0, 0, 0}, 0, 1.5f, {1.0f, 0, 0, 0, 0, 0}, true},
    };
    for (const SliderCase& c : cases) {
        std::array<float, 6> w = c.before;
        EXPECT_EQ(set_emotion_slider(w, c.moved, c.value), c.scaled) << "slider " << c.moved << " to " << c.value;
        float sum = 0;
        for (int i = 0; i < 6; ++i) {
            EXPECT_NEAR(w[std::size_t(i)], c.after[std::size_t(i)], 1e-6f)
                << "slider " << c.moved << " to " << c.value << ", weight " << i;
            sum += w[std::size_t(i)];
        }
        EXPECT_LE(sum, 1.0f + 1e-6f);
    }
}

TEST(ViewerControls, OrbitCameraStartsFrontalAndOrbitsAtItsDistance) {
    const glm::vec3 lo(-80, -120, -90), hi(80, 110, 100);
    const auto frontal = emoface::render::Camera::frontal(lo, hi, 16.0f / 9.0f, 20.0f);
    OrbitCamera cam = OrbitCamera::around(frontal, lo, hi, 20.0f);
    // At yaw = pitch = 0 it is the frontal camera.
    EXPECT_NEAR(glm::length(cam.eye() - frontal.position), 0.0f, 1e-3f);
    const auto view = cam.camera(16.0f / 9.0f).view;
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) EXPECT_NEAR(view[c][r], frontal.view[c][r], 1e-3f) << c << "," << r;

    // Orbiting keeps the distance to the target; a quarter turn looks from the side.
    const float d = cam.distance;
    const float quarter_turn_pixels = (3.14159265f / 2) / 0.008f;
    cam.orbit(-quarter_turn_pixels, 0);  // dragging left turns the camera to the face's left (+x)
    EXPECT_NEAR(glm::length(cam.eye() - cam.target), d, 1e-3f * d);
    EXPECT_NEAR(cam.eye().x - cam.target.x, d, 1e-3f * d);
    EXPECT_NEAR(cam.eye().z - cam.target.z, 0.0f, 1e-3f * d);
    // Pitch stops short of the pole (the up vector would degenerate there).
    cam.orbit(0, 1e6f);
    EXPECT_NEAR(cam.pitch, 85.0f * 3.14159265f / 180.0f, 1e-5f);

    // Zoom: wheel up comes closer, within limits.
    OrbitCamera z = OrbitCamera::around(frontal, lo, hi, 20.0f);
    z.zoom(1);
    EXPECT_NEAR(z.distance, 0.9f * d, 1e-3f * d);
    z.zoom(1000);
    EXPECT_NEAR(z.distance, 0.3f * z.radius, 1e-3f * z.radius);
    z.zoom(-10000);
    EXPECT_NEAR(z.distance, 20.0f * z.radius, 1e-3f * z.radius);

    // Pan moves the target across the view, not along it: dragging right by
    // the window's height moves it the view's height at the target's depth.
    OrbitCamera p = OrbitCamera::around(frontal, lo, hi, 20.0f);
    const glm::vec3 t0 = p.target;
    p.pan(600, 0, 600);
    const float view_height = 2 * d * std::tan(10.0f * 3.14159265f / 180.0f);
    EXPECT_NEAR(p.target.x - t0.x, -view_height, 1e-3f * d);
    EXPECT_NEAR(p.target.y - t0.y, 0.0f, 1e-4f * d);
    EXPECT_NEAR(p.target.z - t0.z, 0.0f, 1e-4f * d);
}

TEST(ViewerControls, LightKeepsItsDirectionAndDragsAroundTheFace) {
    emoface::render::Light light;
    light.position = glm::vec4(glm::normalize(glm::vec3(-0.4f, 0.5f, 1.0f)), 0.0f);
    LightControl l = LightControl::from(light);
    const glm::vec4 d = l.direction();
    EXPECT_NEAR(glm::length(glm::vec3(d) - glm::vec3(light.position)), 0.0f, 1e-5f);
    EXPECT_EQ(d.w, 0.0f);  // directional
    // Dragging up raises the light, dragging right moves it to +x; it stays a unit vector.
    const float elevation = l.elevation;
    l.drag(0, -20);
    EXPECT_GT(l.elevation, elevation);
    const float x = l.direction().x;
    l.drag(20, 0);
    EXPECT_GT(l.direction().x, x);
    EXPECT_NEAR(glm::length(glm::vec3(l.direction())), 1.0f, 1e-5f);
}

// --- emoface view end to end ---------------------------------------------------------

using emoface::testing::CommandResult;
using emoface::testing::EmofaceProcess;
using emoface::testing::run_emoface;

using emoface::testing::on_display;
using emoface::testing::without_display;

class ViewCommand : public ::testing::Test {
protected:
    std::string path(const std::string& name) const { return scratch_.path(name); }

    emoface::testing::ScratchDir scratch_;
};

TEST_F(ViewCommand, WithoutADisplayExits3NamingTheFix) {
    const std::string shot = path("shot.png");
    const CommandResult r = run_emoface({"view", "--quit-after", "3", "--screenshot", shot}, without_display());
    EXPECT_EQ(r.exit_code, 3) << r.err;
    EXPECT_NE(r.err.find("DISPLAY is not set"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("xvfb-run -a emoface view"), std::string::npos) << "names the fix: " << r.err;
    EXPECT_NE(r.err.find("emoface play FILE.fap --out"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
    EXPECT_FALSE(fs::exists(shot));
}

TEST_F(ViewCommand, BadInputExits2BeforeLookingForADisplay) {
    struct Case {
        std::vector<std::string> args;
        std::string message;
    };
    const Case cases[] = {
        {{path("missing.fap")}, "missing.fap"},
        {{"--mix", "0.8 anger + 0.4 fear"}, "emotion mix"},
        {{"--mix", "rage"}, "rage"},
        {{"--size", "10x10"}, "--size"},
        {{"--backend", "gpu"}, "--backend 'gpu'"},
        {{"--wrinkle-size", "100"}, "--wrinkle-size 100"},
        // A missing folder is made; a file in the way is bad input.
        {{"--screenshot", scratch_.write("blocker", "a file") + "/shot.png"}, "is a file, not a folder"},
    };
    for (const Case& c : cases) {
        // No display either: exit 2 (not 3) shows the input is checked first.
        const CommandResult r = run_emoface(emoface::testing::args_with({"view"}, c.args), without_display());
        EXPECT_EQ(r.exit_code, 2) << c.message << ": " << r.err;
        EXPECT_NE(r.err.find(c.message), std::string::npos) << c.message << ": " << r.err;
    }
}

// A private X server for the windowed cases, shared by them.
class ViewUnderXvfb : public ViewCommand {
protected:
    static void SetUpTestSuite() { xvfb_ = std::make_unique<emoface::testing::VirtualDisplay>(1280, 1024); }
    static void TearDownTestSuite() { xvfb_.reset(); }
    void SetUp() override {
        ViewCommand::SetUp();
        if (xvfb_->name().empty()) GTEST_SKIP() << "no virtual X server: " << xvfb_->why();
    }
    static std::unique_ptr<emoface::testing::VirtualDisplay> xvfb_;
};
std::unique_ptr<emoface::testing::VirtualDisplay> ViewUnderXvfb::xvfb_;

int distinct_colours(const ImageRGBA8& img) {
    std::set<std::uint32_t> colours;
    for (std::size_t i = 0; i + 3 < img.pixels.size(); i += 4)
        colours.insert(std::uint32_t(img.pixels[i]) << 16 | std::uint32_t(img.pixels[i + 1]) << 8 | img.pixels[i + 2]);
    return int(colours.size());
}

// The feature points' dots: saturated red no part of the face has.
bool is_dot(const std::uint8_t* rgb) { return rgb[0] > 230 && rgb[1] < 90 && rgb[2] < 80; }

// `view FILE`, and `play FILE` without --out, which opens the same viewer
// with the options given (here the lighter face's).
class ViewOrPlayUnderXvfb : public ViewUnderXvfb, public ::testing::WithParamInterface<const char*> {};

TEST_P(ViewOrPlayUnderXvfb, RendersFramesAndClosesOnItsOwn) {
    const std::string shot = path("shot.png");
    const CommandResult r = run_emoface({GetParam(), EMOFACE_DATA_DIR "/fap/tour.fap", "--size", "480x360",
                                         "--wrinkle-size", "256", "--face-resolution", "0.5", "--quit-after", "3",
                                         "--screenshot", shot},
                                        on_display(xvfb_->name()));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const ImageRGBA8 img = emoface::render::read_image_rgba8(shot);
    EXPECT_EQ(img.width, 480);
    EXPECT_EQ(img.height, 360);
    EXPECT_GT(distinct_colours(img), 200) << "not a uniform image";
    // The face fills the middle: lit skin, brighter than the background
    // (0.16, 0.17, 0.19 sRGB) at the corner.
    const std::uint8_t* centre = img.at(240, 180);
    const std::uint8_t* corner = img.at(470, 350);
    EXPECT_GT(int(centre[0]), int(corner[0]) + 60);
    EXPECT_GT(centre[0], centre[2]) << "skin is warmer than blue";
    int dots = 0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) dots += is_dot(img.at(x, y));
    EXPECT_LT(dots, 10) << "feature points are off unless asked for";
    EXPECT_FALSE(fs::exists(path("imgui.ini"))) << "no settings file left behind";
}
INSTANTIATE_TEST_SUITE_P(Commands, ViewOrPlayUnderXvfb, ::testing::Values("view", "play"));

// What the X server shows in the viewer's window once it is loaded (the
// title says "loading" until then), taken when three grabs over a second
// agree: the picture settled (nothing moves in a view of a still mix).
bool settled_grab(const std::string& display, double seconds, emoface::testing::WindowShot& grab) {
    emoface::testing::WindowShot previous;
    int agreeing = 0;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(long(seconds * 1000));
    while (agreeing < 3 && std::chrono::steady_clock::now() < deadline) {
        if (!emoface::testing::grab_window(display, "emoface view", "loading", 1.0, grab)) continue;
        agreeing = !previous.rgb.empty() && previous.rgb == grab.rgb ? agreeing + 1 : 1;
        previous = grab;
        std::this_thread::sleep_for(std::chrono::milliseconds(500));
    }
    return agreeing >= 3;
}

int count_dots(const emoface::testing::WindowShot& grab) {
    int dots = 0;
    for (std::size_t i = 0; i < grab.rgb.size(); i += 3) dots += is_dot(&grab.rgb[i]);
    return dots;
}

// Pixels of the background's colour (0.16, 0.17, 0.19 sRGB) in the window's
// top half, round the head: the bust's dark navy shirt, lower down, renders
// close to that colour where it turns from the light.
int count_background(const emoface::testing::WindowShot& grab) {
    int n = 0;
    for (std::size_t i = 0; i < grab.rgb.size() / 2; i += 3)
        n += std::abs(grab.rgb[i] - 41) <= 2 && std::abs(grab.rgb[i + 1] - 43) <= 2 &&
             std::abs(grab.rgb[i + 2] - 48) <= 2;
    return n;
}

// The fraction of pixels that differ by more than 8 on some channel (of
// those in the box [x0, x1) x [y0, y1) when one is given).
double fraction_differing(const ImageRGBA8& a, const ImageRGBA8& b, int x0 = 0, int y0 = 0, int x1 = -1,
                          int y1 = -1) {
    emoface::render::ImageDiffOptions options;
    options.pixel_tolerance = 8;
    if (x1 >= 0) options.mask = emoface::render::box_mask(a.width, a.height, x0, y0, x1, y1);
    return emoface::render::diff_images(a, b, options).failing_fraction();
}

TEST_F(ViewUnderXvfb, TheWindowFollowsTheMouseAndClosesWhenAsked) {
    namespace x = emoface::testing;
    const std::string shot = path("shot.png");
    // Killed when it goes out of scope: never left running after a failed assertion.
    EmofaceProcess viewer({"view", "--mix", "0.7 anger + 0.3 fear", "--points", "--lines", "--size", "480x360",
                           "--wrinkle-size", "256", "--screenshot", shot},
                          on_display(xvfb_->name()));
    x::WindowShot frontal;
    if (!settled_grab(xvfb_->name(), 120, frontal))
        FAIL() << "no settled viewer window within 120 s: " << viewer.err_so_far();
    EXPECT_EQ(frontal.title, "emoface view: emotion mix");
    ASSERT_EQ(frontal.width, 480);
    ASSERT_EQ(frontal.height, 360);
    EXPECT_GT(count_dots(frontal), 100) << "--points draws the feature points in the window";

    // Left-drag across the face (below the folded panel) orbits the camera.
    x::WindowShot orbited;
    ASSERT_TRUE(x::drag(xvfb_->name(), "emoface view", 1, 280, 200, 380, 200, 4, 500));
    ASSERT_TRUE(settled_grab(xvfb_->name(), 60, orbited)) << viewer.err_so_far();
    EXPECT_GT(fraction_differing(frontal.image(), orbited.image()), 0.05) << "the face turned";
    EXPECT_GT(count_dots(orbited), 50) << "the feature points follow the turned face";

    // Wheel up zooms in: the face covers more of the window.
    x::WindowShot zoomed;
    ASSERT_TRUE(x::scroll(xvfb_->name(), "emoface view", 280, 200, 3, 500));
    ASSERT_TRUE(settled_grab(xvfb_->name(), 60, zoomed)) << viewer.err_so_far();
    EXPECT_LT(count_background(zoomed), count_background(orbited) * 8 / 10) << "zoomed in";

    ASSERT_TRUE(x::request_close(xvfb_->name(), "emoface view"));
    const CommandResult closed = viewer.wait(60);
    EXPECT_EQ(closed.exit_code, 0) << "closes when the window manager asks: " << closed.err;

    // The screenshot is the frame the window showed last.
    const ImageRGBA8 img = emoface::render::read_image_rgba8(shot);
    ASSERT_EQ(img.width, zoomed.width);
    ASSERT_EQ(img.height, zoomed.height);
    emoface::render::ImageDiffOptions within_two;
    within_two.pixel_tolerance = 2;
    EXPECT_LT(emoface::render::diff_images(img, zoomed.image(), within_two).failing_fraction(), 0.01)
        << "screenshot and window agree";
    if (::testing::Test::HasFailure() || std::getenv("EMOFACE_KEEP_VIEWER_SHOTS")) {
        // The pictures in the working folder, to look at.
        for (const auto* g : {&frontal, &orbited, &zoomed}) {
            const char* name = g == &frontal ? "frontal" : g == &orbited ? "orbited" : "zoomed";
            emoface::render::write_image(std::string("viewer_test_") + name + ".png", g->image());
        }
        fs::copy_file(shot, "viewer_test_screenshot.png", fs::copy_options::overwrite_existing);
    }
}

// --- play and mix open the viewer with every session option ---------------------

// Pixels of `rgb` within 6 of `colour` on each channel.
int count_colour(const ImageRGBA8& img, const std::array<int, 3>& colour) {
    int n = 0;
    for (std::size_t i = 0; i + 3 < img.pixels.size(); i += 4)
        n += std::abs(img.pixels[i] - colour[0]) <= 6 && std::abs(img.pixels[i + 1] - colour[1]) <= 6 &&
             std::abs(img.pixels[i + 2] - colour[2]) <= 6;
    return n;
}

// The acceptance case of the viewer's options: `mix MIX` without --out opens
// the viewer on the key maps of --wrinkles DIR (an artist's folder), not on
// generated ones. The neutral key (the skin under every frame; AU keys add
// their wrinkles to it) is painted one tilted normal everywhere, so the
// morphed map is that colour outside anger's wrinkles: the panel's
// wrinkle-map preview shows it, and the face is lit by it.
TEST_F(ViewUnderXvfb, MixWithoutOutShowsThePaintedWrinkleMaps) {
    const std::string generated = path("generated"), painted = path("painted");
    CommandResult r = run_emoface({"wrinkles", "--size", "256", "--out", generated});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    fs::copy(generated, painted);
    // n = (0.6, 0, 0.8): RGB = 0.5 + 0.5 n, a colour no generated map has
    // over a large area.
    const std::array<int, 3> tilted{204, 128, 230};
    ImageRGBA8 neutral(256, 256);
    for (int y = 0; y < 256; ++y)
        for (int x = 0; x < 256; ++x) {
            std::uint8_t* p = neutral.at(x, y);
            p[0] = std::uint8_t(tilted[0]), p[1] = std::uint8_t(tilted[1]), p[2] = std::uint8_t(tilted[2]), p[3] = 255;
        }
    emoface::render::write_image(painted + "/neutral.png", neutral);

    // Every session option goes through to the viewer (a coarse face, small
    // textures, one sample: fast under llvmpipe).
    auto show = [&](const std::string& keys, const std::string& shot) {
        return run_emoface({"mix", "anger", "--wrinkles", keys, "--wrinkle-map", "--size", "1200x1000",
                            "--face-resolution", "0.5", "--texture-size", "256", "--samples", "1", "--backend",
                            "cpu", "--quit-after", "4", "--screenshot", shot},
                           on_display(xvfb_->name()));
    };
    r = show(painted, path("painted.png"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = show(generated, path("generated.png"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const ImageRGBA8 with_painted = emoface::render::read_image_rgba8(path("painted.png"));
    const ImageRGBA8 with_generated = emoface::render::read_image_rgba8(path("generated.png"));
    ASSERT_EQ(with_painted.width, 1200);
    ASSERT_EQ(with_painted.height, 1000);
    // The preview (about 360 x 360 in the panel) shows the painted colour.
    EXPECT_GT(count_colour(with_painted, tilted), 40000) << "the painted map in the panel's preview";
    EXPECT_LT(count_colour(with_generated, tilted), 4000) << "generated keys look otherwise";
    // The face in the middle (right of the panel) is lit by the painted map.
    EXPECT_GT(fraction_differing(with_painted, with_generated, 520, 400, 680, 600), 0.3);
    if (::testing::Test::HasFailure() || std::getenv("EMOFACE_KEEP_VIEWER_SHOTS")) {
        fs::copy_file(path("painted.png"), "viewer_test_painted.png", fs::copy_options::overwrite_existing);
        fs::copy_file(path("generated.png"), "viewer_test_generated.png", fs::copy_options::overwrite_existing);
    }
}

// `mix` with AU terms and no --out opens the viewer with the AUs on top of
// the emotions (issue 11; they were dropped, leaving joy alone): AU4 lowers
// and draws the brows together, so the face differs from plain joy's.
TEST_F(ViewUnderXvfb, MixWithoutOutShowsItsActionUnits) {
    auto show = [&](const std::string& mix, const std::string& shot) {
        return run_emoface({"mix", mix, "--size", "1200x1000", "--face-resolution", "0.5", "--texture-size", "256",
                            "--wrinkle-size", "256", "--samples", "1", "--backend", "cpu", "--quit-after", "4",
                            "--screenshot", shot},
                           on_display(xvfb_->name()));
    };
    CommandResult r = show("0.6 joy + 1 AU4", path("au.png"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = show("0.6 joy", path("joy.png"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const ImageRGBA8 with_au = emoface::render::read_image_rgba8(path("au.png"));
    const ImageRGBA8 joy = emoface::render::read_image_rgba8(path("joy.png"));
    // The face's upper half, right of the panel (whose AU line differs too).
    EXPECT_GT(fraction_differing(with_au, joy, 480, 200, 1100, 560), 0.01) << "the brows moved";
    if (::testing::Test::HasFailure() || std::getenv("EMOFACE_KEEP_VIEWER_SHOTS")) {
        fs::copy_file(path("au.png"), "viewer_test_au4.png", fs::copy_options::overwrite_existing);
        fs::copy_file(path("joy.png"), "viewer_test_joy.png", fs::copy_options::overwrite_existing);
    }
}

}  // namespace
