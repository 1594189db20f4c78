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
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

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

#include "emoface/render/image_io.h"
#include "emoface/render/renderer.h"
#include "viewer_controls.h"
#include "viewer_x11.h"

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

struct Result {
    int rc;
    std::string err;
};

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// The binary keeps ASan's checks but not LeakSanitizer's: GL drivers keep
// one-time allocations past exit.
std::string command_line(const std::string& args, const fs::path& err) {
    return "ASAN_OPTIONS=\"${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0\" '" + std::string(EMOFACE_BINARY) +
           "' " + args + " >/dev/null 2>'" + err.string() + "'";
}

class ViewCommand : public ::testing::Test {
protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() / ("emoface_viewer_" + std::to_string(::getpid()) + "_" + info->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    // Runs `emoface ARGS` to the end with `env` before it ("env -u DISPLAY").
    Result run(const std::string& args, const std::string& env) {
        const fs::path err = dir_ / "stderr";
        const int status = std::system((env + " " + command_line(args, err)).c_str());
        return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(err)};
    }

    // Starts `emoface ARGS` on `display` without waiting for it.
    pid_t start(const std::string& args, const std::string& display) {
        const std::string cmd = command_line(args, dir_ / "stderr");
        const pid_t pid = ::fork();
        if (pid == 0) {
            ::setenv("DISPLAY", display.c_str(), 1);
            ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
            ::_exit(127);
        }
        return pid;
    }

    // The exit code of a started command; killed (and -1) after `seconds`.
    static int finish(pid_t pid, double seconds) {
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(long(seconds * 1000));
        int status = 0;
        while (::waitpid(pid, &status, WNOHANG) == 0) {
            if (std::chrono::steady_clock::now() > deadline) {
                ::kill(pid, SIGKILL);
                ::waitpid(pid, &status, 0);
                return -1;
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(50));
        }
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    }

    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    std::string err() const { return slurp(dir_ / "stderr"); }

    fs::path dir_;
};

TEST_F(ViewCommand, WithoutADisplayExits3NamingTheFix) {
    const std::string shot = path("shot.png");
    const Result r = run("view --quit-after 3 --screenshot '" + shot + "'", "env -u DISPLAY");
    EXPECT_EQ(r.rc, 3) << r.err;
    EXPECT_NE(r.err.find("DISPLAY is not set"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("xvfb-run -a emoface view"), std::string::npos) << "names the fix: " << r.err;
    EXPECT_NE(r.err.find("emoface play FILE.fap --out"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
    EXPECT_FALSE(fs::exists(shot));
}

TEST_F(ViewCommand, BadInputExits2BeforeLookingForADisplay) {
    struct Case {
        std::string args, message;
    };
    const Case cases[] = {
        {"'" + path("missing.fap") + "'", "missing.fap"},
        {"--mix '0.8 anger + 0.4 fear'", "emotion mix"},
        {"--mix 'rage'", "rage"},
        {"--size 10x10", "--size"},
        {"--backend gpu", "--backend 'gpu'"},
        {"--wrinkle-size 100", "--wrinkle-size 100"},
        {"--screenshot '" + path("no/such/folder/shot.png") + "'", "no/such/folder"},
    };
    for (const Case& c : cases) {
        // No display either: exit 2 (not 3) shows the input is checked first.
        const Result r = run("view " + c.args, "env -u DISPLAY");
        EXPECT_EQ(r.rc, 2) << c.args << ": " << r.err;
        EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << ": " << r.err;
    }
}

// A private X server for the windowed cases, shared by them.
class ViewUnderXvfb : public ViewCommand {
protected:
    static void SetUpTestSuite() { xvfb_ = std::make_unique<emoface::apps::testing::VirtualDisplay>(1280, 1024); }
    static void TearDownTestSuite() { xvfb_.reset(); }
    void SetUp() override {
        ViewCommand::SetUp();
        if (xvfb_->name().empty()) GTEST_SKIP() << "no virtual X server: " << xvfb_->why();
    }
    static std::unique_ptr<emoface::apps::testing::VirtualDisplay> xvfb_;
};
std::unique_ptr<emoface::apps::testing::VirtualDisplay> ViewUnderXvfb::xvfb_;

int distinct_colours(const ImageRGBA8& img) {
    std::set<std::uint32_t> colours;
    for (std::size_t i = 0; i + 3 < img.pixels.size(); i += 4)
        colours.insert(std::uint32_t(img.pixels[i]) << 16 | std::uint32_t(img.pixels[i + 1]) << 8 | img.pixels[i + 2]);
    return int(colours.size());
}

// The feature points' dots: saturated red no part of the face has.
bool is_dot(const std::uint8_t* rgb) { return rgb[0] > 230 && rgb[1] < 90 && rgb[2] < 80; }

TEST_F(ViewUnderXvfb, RendersFramesAndClosesOnItsOwn) {
    const std::string shot = path("shot.png");
    const Result r = run("view '" EMOFACE_DATA_DIR "/fap/tour.fap' --size 480x360 --wrinkle-size 256 --quit-after 3 "
                         "--screenshot '" + shot + "'",
                         "DISPLAY=" + xvfb_->name());
    ASSERT_EQ(r.rc, 0) << r.err;
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

// What the X server shows in the viewer's window once it is loaded (the
// title says "loading" until then), taken when three grabs over a second
// agree: the picture settled (nothing moves in a view of a still mix).
bool settled_grab(const std::string& display, double seconds, emoface::apps::testing::WindowShot& grab) {
    emoface::apps::testing::WindowShot previous;
    int agreeing = 0;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(long(seconds * 1000));
    while (agreeing < 3 && std::chrono::steady_clock::now() < deadline) {
        if (!emoface::apps::testing::grab_window(display, "emoface view", "loading", 1.0, grab)) continue;
        agreeing = !previous.rgb.empty() && previous.rgb == grab.rgb ? agreeing + 1 : 1;
        previous = grab;
        std::this_thread::sleep_for(std::chrono::milliseconds(500));
    }
    return agreeing >= 3;
}

int count_dots(const emoface::apps::testing::WindowShot& grab) {
    int dots = 0;
    for (std::size_t i = 0; i < grab.rgb.size(); i += 3) dots += is_dot(&grab.rgb[i]);
    return dots;
}

// Pixels of the background's colour (0.16, 0.17, 0.19 sRGB).
int count_background(const emoface::apps::testing::WindowShot& grab) {
    int n = 0;
    for (std::size_t i = 0; i < grab.rgb.size(); i += 3)
        n += std::abs(grab.rgb[i] - 41) <= 2 && std::abs(grab.rgb[i + 1] - 43) <= 2 &&
             std::abs(grab.rgb[i + 2] - 48) <= 2;
    return n;
}

double fraction_differing(const emoface::apps::testing::WindowShot& a, const emoface::apps::testing::WindowShot& b) {
    if (a.rgb.size() != b.rgb.size() || a.rgb.empty()) return 1.0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < a.rgb.size(); i += 3)
        n += std::abs(a.rgb[i] - b.rgb[i]) > 8 || std::abs(a.rgb[i + 1] - b.rgb[i + 1]) > 8 ||
             std::abs(a.rgb[i + 2] - b.rgb[i + 2]) > 8;
    return double(n) / double(a.rgb.size() / 3);
}

TEST_F(ViewUnderXvfb, TheWindowFollowsTheMouseAndClosesWhenAsked) {
    namespace x = emoface::apps::testing;
    const std::string shot = path("shot.png");
    const pid_t pid = start("view --mix '0.7 anger + 0.3 fear' --points --lines --size 480x360 --wrinkle-size 256 "
                            "--screenshot '" + shot + "'",
                            xvfb_->name());
    ASSERT_GT(pid, 0);
    struct Stop {  // never leave the viewer running after a failed assertion
        pid_t pid;
        ~Stop() { ViewCommand::finish(pid, 0); }
    };
    x::WindowShot frontal;
    if (!settled_grab(xvfb_->name(), 120, frontal)) {
        Stop{pid};
        FAIL() << "no settled viewer window within 120 s: " << err();
    }
    EXPECT_EQ(frontal.title, "emoface view: emotion mix");
    ASSERT_EQ(frontal.width, 480);
    ASSERT_EQ(frontal.height, 360);
    EXPECT_GT(count_dots(frontal), 100) << "--points draws the feature points in the window";

    // Left-drag across the face (below the folded panel) orbits the camera.
    x::WindowShot orbited;
    ASSERT_TRUE(x::drag(xvfb_->name(), "emoface view", 1, 280, 200, 380, 200, 4, 500));
    ASSERT_TRUE(settled_grab(xvfb_->name(), 60, orbited)) << err();
    EXPECT_GT(fraction_differing(frontal, orbited), 0.05) << "the face turned";
    EXPECT_GT(count_dots(orbited), 50) << "the feature points follow the turned face";

    // Wheel up zooms in: the face covers more of the window.
    x::WindowShot zoomed;
    ASSERT_TRUE(x::scroll(xvfb_->name(), "emoface view", 280, 200, 3, 500));
    ASSERT_TRUE(settled_grab(xvfb_->name(), 60, zoomed)) << err();
    EXPECT_LT(count_background(zoomed), count_background(orbited) * 8 / 10) << "zoomed in";

    ASSERT_TRUE(x::request_close(xvfb_->name(), "emoface view"));
    EXPECT_EQ(ViewCommand::finish(pid, 60), 0) << "closes when the window manager asks: " << err();

    // The screenshot is the frame the window showed last.
    const ImageRGBA8 img = emoface::render::read_image_rgba8(shot);
    ASSERT_EQ(img.width, zoomed.width);
    ASSERT_EQ(img.height, zoomed.height);
    int same = 0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const std::uint8_t* s = img.at(x, y);
            const std::uint8_t* g = &zoomed.rgb[(std::size_t(y) * std::size_t(zoomed.width) + std::size_t(x)) * 3];
            same += std::abs(s[0] - g[0]) <= 2 && std::abs(s[1] - g[1]) <= 2 && std::abs(s[2] - g[2]) <= 2;
        }
    EXPECT_GT(same, img.width * img.height * 99 / 100) << "screenshot and window agree";
    if (::testing::Test::HasFailure() || std::getenv("EMOFACE_KEEP_VIEWER_SHOTS")) {
        // The pictures in the working folder, to look at.
        for (const auto* g : {&frontal, &orbited, &zoomed}) {
            ImageRGBA8 window(g->width, g->height);
            for (std::size_t i = 0; i < std::size_t(g->width) * std::size_t(g->height); ++i) {
                std::copy_n(&g->rgb[3 * i], 3, &window.pixels[4 * i]);
                window.pixels[4 * i + 3] = 255;
            }
            const char* name = g == &frontal ? "frontal" : g == &orbited ? "orbited" : "zoomed";
            emoface::render::write_image(std::string("viewer_test_") + name + ".png", window);
        }
        fs::copy_file(shot, "viewer_test_screenshot.png", fs::copy_options::overwrite_existing);
    }
}

}  // namespace
