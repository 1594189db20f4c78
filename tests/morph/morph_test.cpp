// morph on the CPU backend: identities, analytic maps, blending, normal maps,
// agreement with the double-precision reference, the fast mode, bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "emoface/common/error.h"
#include "emoface/morph/morph.h"
#include "emoface/morph/reference.h"
#include "morph_test_util.h"

namespace emoface::morph {
namespace {

using namespace test;

KeyMap key(const void* pixels, Layout layout) {
    KeyMap k;
    k.pixels = pixels;
    k.layout = std::move(layout);
    return k;
}

// Double bilinear sample, clamp to edge, pixel centres at i + 0.5: what the
// output must hold where the warp sends a pixel to (px, py).
double sample(const std::vector<std::uint8_t>& img, int w, int h, double px, double py, int c) {
    const double fx = std::fmin(std::fmax(px - 0.5, 0.0), w - 1.0);
    const double fy = std::fmin(std::fmax(py - 0.5, 0.0), h - 1.0);
    const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
    const int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
    const double tx = fx - x0, ty = fy - y0;
    auto at = [&](int x, int y) { return static_cast<double>(img[(static_cast<std::size_t>(y) * w + x) * 4 + c]); };
    return (1 - ty) * ((1 - tx) * at(x0, y0) + tx * at(x1, y0)) + ty * ((1 - tx) * at(x0, y1) + tx * at(x1, y1));
}

// ---- identity ----------------------------------------------------------------

TEST(MorphIdentity, TargetEqualToSourceGivesTheSourceBack) {
    const int w = 64, h = 48;
    const auto img = random_rgba8(w, h, 1);
    const Layout layout = random_layout(12, 2);
    Morpher m(w, h, PixelFormat::Rgba8, {key(img.data(), layout)}, Backend::Cpu);
    std::vector<std::uint8_t> out(img.size());
    for (Accuracy acc : {Accuracy::Exact, Accuracy::Fast}) {
        MorphParams params;
        params.accuracy = acc;
        m.morph_to_host(layout, {1.0f}, params, out.data());
        // The displacement is exactly 0 (the line table holds exact zeros), so
        // every pixel samples its own centre: not even rounding differs.
        EXPECT_EQ(max_abs_diff(out, img), 0.0) << to_string(acc);
    }
}

TEST(MorphIdentity, FloatKeysAndSeveralSourcesBlendInPlace) {
    const int w = 40, h = 40;
    const auto a = to_float(random_rgba8(w, h, 3)), b = to_float(random_rgba8(w, h, 4)),
               c = to_float(random_rgba8(w, h, 5));
    const Layout layout = random_layout(7, 6);
    Morpher m(w, h, PixelFormat::RgbaF32, {key(a.data(), layout), key(b.data(), layout), key(c.data(), layout)},
              Backend::Cpu);
    std::vector<float> out(a.size());
    m.morph_to_host(layout, {0.2f, 0.3f, 0.5f}, {}, out.data());
    std::vector<float> expected(a.size());
    for (std::size_t i = 0; i < a.size(); ++i) expected[i] = 0.2f * a[i] + 0.3f * b[i] + 0.5f * c[i];
    EXPECT_LT(max_abs_diff(out, expected), 1e-6);
}

TEST(MorphIdentity, NoLinesIsAPlainBlend) {
    const int w = 24, h = 20;
    const auto a = to_float(random_rgba8(w, h, 7)), b = to_float(random_rgba8(w, h, 8));
    Morpher m(w, h, PixelFormat::RgbaF32, {key(a.data(), {}), key(b.data(), {})}, Backend::Cpu);
    EXPECT_EQ(m.lines(), 0);
    std::vector<float> out(a.size()), expected(a.size());
    for (std::size_t i = 0; i < a.size(); ++i) expected[i] = 0.25f * a[i] + 0.75f * b[i];
    for (Accuracy acc : {Accuracy::Exact, Accuracy::Fast}) {
        MorphParams params;
        params.accuracy = acc;
        m.morph_to_host({}, {0.25f, 0.75f}, params, out.data());
        EXPECT_LT(max_abs_diff(out, expected), 1e-6) << to_string(acc);
    }
}

// ---- analytic maps -------------------------------------------------------------

struct AnalyticCase {
    const char* name;
    int width, height;
    Layout target;
    Layout source;
    std::function<void(double x, double y, double& sx, double& sy)> map;  // pixel coordinates
};

Layout horizontal_lines(int n, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> pos(0.1f, 0.9f), len(0.1f, 0.3f);
    Layout l;
    for (int i = 0; i < n; ++i) {
        const float x = pos(rng), y = pos(rng);
        l.push_back({x, y, x + len(rng), y});
    }
    return l;
}

std::vector<AnalyticCase> analytic_cases() {
    std::vector<AnalyticCase> cases;
    {  // translation by (5, -3) pixels on a non-square image
        const int w = 80, h = 50;
        const Layout t = random_layout(10, 11);
        Layout s = t;
        for (Line& l : s) {
            l.px += 5.0f / w;
            l.qx += 5.0f / w;
            l.py -= 3.0f / h;
            l.qy -= 3.0f / h;
        }
        cases.push_back({"translation", w, h, t, s, [](double x, double y, double& sx, double& sy) {
                             sx = x + 5.0;
                             sy = y - 3.0;
                         }});
    }
    {  // rotation by 20 degrees about the centre
        const int w = 64, h = 64;
        const Layout t = random_layout(10, 12);
        const double th = 20.0 * 3.14159265358979 / 180.0, c = std::cos(th), s_ = std::sin(th);
        auto rot = [=](float& x, float& y) {
            const double dx = x - 0.5, dy = y - 0.5;
            x = static_cast<float>(0.5 + c * dx - s_ * dy);
            y = static_cast<float>(0.5 + s_ * dx + c * dy);
        };
        Layout s = t;
        for (Line& l : s) {
            rot(l.px, l.py);
            rot(l.qx, l.qy);
        }
        cases.push_back({"rotation", w, h, t, s, [=](double x, double y, double& sx, double& sy) {
                             const double dx = x - 32.0, dy = y - 32.0;
                             sx = 32.0 + c * dx - s_ * dy;
                             sy = 32.0 + s_ * dx + c * dy;
                         }});
    }
    {  // scaling by 1.25 along the lines (all horizontal) about x = 0.5.
        // Beier-Neely keeps the distance across a line (v) unscaled, so a
        // uniform scale is reproduced only on the lines; along the lines'
        // direction it is exact everywhere.
        const int w = 64, h = 40;
        const Layout t = horizontal_lines(8, 13);
        Layout s = t;
        for (Line& l : s) {
            l.px = 0.5f + 1.25f * (l.px - 0.5f);
            l.qx = 0.5f + 1.25f * (l.qx - 0.5f);
        }
        cases.push_back({"scaling along the lines", w, h, t, s, [](double x, double y, double& sx, double& sy) {
                             sx = 32.0 + 1.25 * (x - 32.0);
                             sy = y;
                         }});
    }
    return cases;
}

TEST(MorphAnalytic, SimilarityOfAllLinesMovesTheImageAccordingly) {
    for (const AnalyticCase& c : analytic_cases()) {
        SCOPED_TRACE(c.name);
        const auto img = random_rgba8(c.width, c.height, 21);
        Morpher m(c.width, c.height, PixelFormat::Rgba8, {key(img.data(), c.source)}, Backend::Cpu);
        std::vector<float> pos(static_cast<std::size_t>(c.width) * c.height * 2);
        m.positions_to_host(c.target, {}, pos.data());
        std::vector<std::uint8_t> out(img.size());
        m.morph_to_host(c.target, {1.0f}, {}, out.data());
        double worst_pos = 0.0, worst_value = 0.0;
        for (int y = 0; y < c.height; ++y)
            for (int x = 0; x < c.width; ++x) {
                double sx, sy;
                c.map(x + 0.5, y + 0.5, sx, sy);
                const std::size_t i = static_cast<std::size_t>(y) * c.width + x;
                worst_pos = std::fmax(worst_pos, std::hypot(pos[2 * i] - sx, pos[2 * i + 1] - sy));
                for (int ch = 0; ch < 4; ++ch)
                    worst_value = std::fmax(worst_value, std::fabs(out[4 * i + ch] - sample(img, c.width, c.height,
                                                                                             sx, sy, ch)));
            }
        EXPECT_LT(worst_pos, 1e-3) << "pixels";
        EXPECT_LE(worst_value, 1.0) << "LSB";
    }
}

// ---- blending ----------------------------------------------------------------------

TEST(MorphBlend, WeightsOneZeroEqualTheSingleSourceWarp) {
    const int w = 48, h = 48;
    const auto a = random_rgba8(w, h, 31), b = random_rgba8(w, h, 32);
    const Layout la = random_layout(9, 33), lb = jitter(la, 0.05f, 34), target = jitter(la, 0.04f, 35);
    Morpher two(w, h, PixelFormat::Rgba8, {key(a.data(), la), key(b.data(), lb)}, Backend::Cpu);
    Morpher one(w, h, PixelFormat::Rgba8, {key(a.data(), la)}, Backend::Cpu);
    std::vector<std::uint8_t> out2(a.size()), out1(a.size());
    for (Accuracy acc : {Accuracy::Exact, Accuracy::Fast}) {
        MorphParams params;
        params.accuracy = acc;
        two.morph_to_host(target, {1.0f, 0.0f}, params, out2.data());
        one.morph_to_host(target, {1.0f}, params, out1.data());
        EXPECT_EQ(max_abs_diff(out2, out1), 0.0) << to_string(acc);
    }
}

TEST(MorphBlend, WeightsSummingToOneBlendTheWarpedSources) {
    const int w = 48, h = 40;
    const auto a = to_float(random_rgba8(w, h, 41)), b = to_float(random_rgba8(w, h, 42));
    const Layout la = random_layout(9, 43), lb = jitter(la, 0.05f, 44), target = jitter(la, 0.04f, 45);
    Morpher m(w, h, PixelFormat::RgbaF32, {key(a.data(), la), key(b.data(), lb)}, Backend::Cpu);
    std::vector<float> wa(a.size()), wb(a.size()), mix(a.size());
    m.morph_to_host(target, {1.0f, 0.0f}, {}, wa.data());
    m.morph_to_host(target, {0.0f, 1.0f}, {}, wb.data());
    for (float t : {0.25f, 0.5f, 0.9f}) {
        m.morph_to_host(target, {1.0f - t, t}, {}, mix.data());
        std::vector<float> expected(a.size());
        for (std::size_t i = 0; i < a.size(); ++i) expected[i] = (1.0f - t) * wa[i] + t * wb[i];
        EXPECT_LT(max_abs_diff(mix, expected), 1e-5) << "t = " << t;
    }
}

TEST(MorphBlend, NormalMapsStayUnitLength) {
    const int w = 40, h = 32;
    const auto n0 = random_normals(w, h, 51), n1 = random_normals(w, h, 52), n2 = random_normals(w, h, 53);
    const auto q0 = quantise(n0), q1 = quantise(n1), q2 = quantise(n2);
    const Layout l0 = random_layout(8, 54), l1 = jitter(l0, 0.05f, 55), l2 = jitter(l0, 0.05f, 56);
    const Layout target = jitter(l0, 0.03f, 57);
    MorphParams params;
    params.normal_map = true;
    const std::vector<float> weights{0.3f, 0.3f, 0.4f};
    struct Case {
        PixelFormat format;
        const void* k0;
        const void* k1;
        const void* k2;
        double unit, tolerance;  // RGBA8: each component rounds by half an LSB
    };
    for (const Case& c : {Case{PixelFormat::RgbaF32, n0.data(), n1.data(), n2.data(), 1.0, 1e-5},
                          Case{PixelFormat::Rgba8, q0.data(), q1.data(), q2.data(), 255.0, 0.01}}) {
        SCOPED_TRACE(to_string(c.format));
        for (Accuracy acc : {Accuracy::Exact, Accuracy::Fast}) {
            params.accuracy = acc;
            Morpher m(w, h, c.format, {key(c.k0, l0), key(c.k1, l1), key(c.k2, l2)}, Backend::Cpu);
            std::vector<float> fout(static_cast<std::size_t>(w) * h * 4);
            std::vector<std::uint8_t> bout(fout.size());
            void* out = c.format == PixelFormat::RgbaF32 ? static_cast<void*>(fout.data()) : bout.data();
            m.morph_to_host(target, weights, params, out);
            double worst = 0.0;
            for (std::size_t i = 0; i < fout.size() / 4; ++i) {
                double n2sum = 0.0;
                for (int ch = 0; ch < 3; ++ch) {
                    const double v = c.format == PixelFormat::RgbaF32 ? fout[4 * i + ch] : bout[4 * i + ch];
                    const double comp = 2.0 * v / c.unit - 1.0;
                    n2sum += comp * comp;
                }
                worst = std::fmax(worst, std::fabs(std::sqrt(n2sum) - 1.0));
            }
            EXPECT_LT(worst, c.tolerance) << to_string(acc);
        }
    }
}

// ---- against the double reference ---------------------------------------------

struct ReferenceCase {
    const char* name;
    int width, height, keys, lines;
    float a, b, p;
};

class MorphReference : public ::testing::TestWithParam<ReferenceCase> {};

TEST_P(MorphReference, PositionsWithin1e3PixelAndPixelsWithin1Lsb) {
    const ReferenceCase& c = GetParam();
    std::vector<std::vector<std::uint8_t>> images;
    std::vector<KeyMap> keys;
    std::vector<Layout> layouts;
    const Layout base = random_layout(c.lines, 61);
    for (int k = 0; k < c.keys; ++k) {
        images.push_back(random_rgba8(c.width, c.height, 62 + k));
        layouts.push_back(jitter(base, 0.06f, 70 + k));
    }
    for (int k = 0; k < c.keys; ++k) keys.push_back(key(images[k].data(), layouts[k]));
    const Layout target = jitter(base, 0.04f, 80);
    MorphParams params;
    params.a = c.a;
    params.b = c.b;
    params.p = c.p;
    std::vector<float> weights(c.keys, 1.0f / c.keys);

    Morpher m(c.width, c.height, PixelFormat::Rgba8, keys, Backend::Cpu);
    std::vector<float> pos(static_cast<std::size_t>(c.width) * c.height * c.keys * 2);
    m.positions_to_host(target, params, pos.data());
    std::vector<double> ref_pos;
    reference_positions(c.width, c.height, layouts, target, params, ref_pos);
    double worst = 0.0;
    for (std::size_t i = 0; i < pos.size(); ++i) worst = std::fmax(worst, std::fabs(pos[i] - ref_pos[i]));
    EXPECT_LT(worst, 1e-3) << "pixels";

    std::vector<std::uint8_t> out(images[0].size()), ref(images[0].size());
    m.morph_to_host(target, weights, params, out.data());
    reference_morph(c.width, c.height, PixelFormat::Rgba8, keys, target, weights, params, ref.data());
    EXPECT_LE(max_abs_diff(out, ref), 1.0) << "LSB";
}

INSTANTIATE_TEST_SUITE_P(
    Cases, MorphReference,
    ::testing::Values(ReferenceCase{"square_K1", 64, 64, 1, 12, 0.01f, 2.0f, 0.5f},
                      ReferenceCase{"wide_K3", 96, 40, 3, 10, 0.01f, 2.0f, 0.5f},
                      ReferenceCase{"tall_K2_b1p3", 36, 70, 2, 9, 0.02f, 1.3f, 0.0f},
                      ReferenceCase{"K8_p1", 32, 32, 8, 6, 0.005f, 2.0f, 1.0f},
                      ReferenceCase{"sharp_a_b0p5", 50, 50, 2, 15, 0.001f, 0.5f, 0.7f}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(MorphReferenceFloat, FloatKeysMatchTheReference) {
    const int w = 48, h = 36;
    const auto a = to_float(random_rgba8(w, h, 91)), b = to_float(random_rgba8(w, h, 92));
    const Layout la = random_layout(8, 93), lb = jitter(la, 0.05f, 94), target = jitter(la, 0.03f, 95);
    const std::vector<KeyMap> keys{key(a.data(), la), key(b.data(), lb)};
    Morpher m(w, h, PixelFormat::RgbaF32, keys, Backend::Cpu);
    std::vector<float> out(a.size()), ref(a.size());
    m.morph_to_host(target, {0.6f, 0.4f}, {}, out.data());
    reference_morph(w, h, PixelFormat::RgbaF32, keys, target, {0.6f, 0.4f}, {}, ref.data());
    EXPECT_LT(max_abs_diff(out, ref), 1e-4);
}

// ---- fast mode -------------------------------------------------------------------------

TEST(MorphFast, AffineFieldsAreInterpolatedExactly) {
    // A translation makes every line's displacement the same constant, so the
    // grid interpolates it without error.
    const AnalyticCase c = analytic_cases()[0];
    const auto img = random_rgba8(c.width, c.height, 101);
    Morpher m(c.width, c.height, PixelFormat::Rgba8, {key(img.data(), c.source)}, Backend::Cpu);
    std::vector<float> exact(static_cast<std::size_t>(c.width) * c.height * 2), fast(exact.size());
    MorphParams params;
    m.positions_to_host(c.target, params, exact.data());
    params.accuracy = Accuracy::Fast;
    for (int cell : {4, 8, 16, 32}) {
        params.fast_cell = cell;
        m.positions_to_host(c.target, params, fast.data());
        EXPECT_LT(max_abs_diff(exact, fast), 1e-3) << "cell " << cell;
    }
}

TEST(MorphFast, ExactNearLinesBoundTheError) {
    const int w = 160, h = 128;
    const auto img = random_rgba8(w, h, 111);
    const Layout base = random_layout(12, 112), target = jitter(base, 0.03f, 113);
    Morpher m(w, h, PixelFormat::Rgba8, {key(img.data(), base)}, Backend::Cpu);
    std::vector<float> exact(static_cast<std::size_t>(w) * h * 2), fast(exact.size());
    MorphParams params;
    m.positions_to_host(target, params, exact.data());
    params.accuracy = Accuracy::Fast;
    params.fast_cell = 8;
    auto errors = [&](float reach, double& worst, double& at_grid) {
        params.fast_reach = reach;
        m.positions_to_host(target, params, fast.data());
        worst = at_grid = 0.0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const std::size_t i = (static_cast<std::size_t>(y) * w + x) * 2;
                const double e = std::hypot(fast[i] - exact[i], fast[i + 1] - exact[i + 1]);
                worst = std::fmax(worst, e);
                if (x % 8 == 0 && y % 8 == 0) at_grid = std::fmax(at_grid, e);
            }
    };
    double plain, plain_grid, near1, near1_grid, near4, near4_grid, all, all_grid;
    errors(0.0f, plain, plain_grid);  // plain interpolation: the kinks across lines are smoothed over
    errors(1.0f, near1, near1_grid);
    errors(4.0f, near4, near4_grid);
    errors(64.0f, all, all_grid);  // every line near every cell: exact everywhere
    EXPECT_LT(plain_grid, 1e-3) << "grid points are evaluated exactly";
    EXPECT_LT(near4_grid, 1e-3);
    EXPECT_GT(plain, 0.1) << "a test layout with nothing to interpolate proves nothing";
    EXPECT_LT(near1, plain);
    EXPECT_LT(near4, near1);
    EXPECT_LT(near4, 0.1);
    EXPECT_LT(all, 1e-3);
}

// ---- backends ------------------------------------------------------------------------

TEST(MorphBackend, AutoFallsBackToTheCpuWithoutADevice) {
    if (cuda_available()) GTEST_SKIP() << "a CUDA device is present: " << cuda_device_description();
    const auto img = random_rgba8(8, 8, 121);
    Morpher m(8, 8, PixelFormat::Rgba8, {key(img.data(), random_layout(2, 122))});
    EXPECT_EQ(m.backend(), Backend::Cpu);
}

// A fresh process (the "threadsafe" death-test style runs the test in a new
// one), so the once-per-process notice has not been printed yet.
TEST(MorphBackendDeathTest, AutoWithoutADeviceSaysOncePlainlyThatTheMorphRunsOnTheCpu) {
    if (cuda_available()) GTEST_SKIP() << "a CUDA device is present: " << cuda_device_description();
    GTEST_FLAG_SET(death_test_style, "threadsafe");
    const auto img = random_rgba8(8, 8, 125);
    EXPECT_EXIT(
        {
            for (int i = 0; i < 3; ++i) Morpher m(8, 8, PixelFormat::Rgba8, {key(img.data(), random_layout(2, 126))});
            std::exit(0);
        },
        ::testing::ExitedWithCode(0),
        // The whole of stderr: one line (POSIX regex, ^ and $ at its ends).
        "^(no NVIDIA GPU found|the NVIDIA GPU cannot run this build's CUDA code|this build has no CUDA backend): "
        "the morph runs on the CPU\n$");
}

TEST(MorphBackend, CudaWithoutADeviceIsAnEnvironmentErrorNamingTheFix) {
    if (cuda_available()) GTEST_SKIP() << "a CUDA device is present: " << cuda_device_description();
    const auto img = random_rgba8(8, 8, 123);
    try {
        Morpher m(8, 8, PixelFormat::Rgba8, {key(img.data(), random_layout(2, 124))}, Backend::Cuda);
        FAIL() << "expected an EnvironmentError";
    } catch (const EnvironmentError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("morph: Morpher(): Backend::Cuda asked for, but"), std::string::npos) << what;
        EXPECT_NE(what.find("Backend::Cpu"), std::string::npos) << what;
    }
}

TEST(MorphBackend, ResultsDoNotDependOnTheThreadSchedule) {
    const int w = 70, h = 53;
    const auto img = random_rgba8(w, h, 131);
    const Layout base = random_layout(10, 132), target = jitter(base, 0.05f, 133);
    Morpher m(w, h, PixelFormat::Rgba8, {key(img.data(), base)}, Backend::Cpu);
    std::vector<std::uint8_t> first(img.size()), again(img.size());
    m.morph_to_host(target, {1.0f}, {}, first.data());
    for (int i = 0; i < 5; ++i) {
        m.morph_to_host(target, {1.0f}, {}, again.data());
        ASSERT_EQ(max_abs_diff(first, again), 0.0);
    }
}

// ---- CPU instruction sets ----------------------------------------------------------
//
// The CPU row loops are built twice, for AVX2 + FMA and for the target's
// baseline; a processor with AVX2 runs the first. EMOFACE_MORPH_BASELINE=1
// forces the baseline loops so this (Release) run tests them too.

// Sets an environment variable for a scope and restores it after.
class ScopedEnv {
public:
    ScopedEnv(const char* name, const char* value) : name_(name) {
        if (const char* old = std::getenv(name)) old_ = old;
        if (value != nullptr)
            ::setenv(name, value, 1);
        else
            ::unsetenv(name);
    }
    ~ScopedEnv() {
        if (old_.has_value())
            ::setenv(name_, old_->c_str(), 1);
        else
            ::unsetenv(name_);
    }
    ScopedEnv(const ScopedEnv&) = delete;
    ScopedEnv& operator=(const ScopedEnv&) = delete;

private:
    const char* name_;
    std::optional<std::string> old_;
};

TEST(MorphCpuPath, BaselineSwitchPicksTheBaselineLoops) {
    {
        ScopedEnv env("EMOFACE_MORPH_BASELINE", "1");
        EXPECT_STREQ(cpu_kernels_name(), "baseline");
    }
    std::string usual;
    {
        ScopedEnv env("EMOFACE_MORPH_BASELINE", nullptr);
        usual = cpu_kernels_name();
    }
    EXPECT_TRUE(usual == "avx2" || usual == "baseline") << usual;
    ScopedEnv env("EMOFACE_MORPH_BASELINE", "0");  // only "1" switches
    EXPECT_EQ(cpu_kernels_name(), usual);
}

struct CpuPathCase {
    const char* name;
    int width, height, keys, lines;
    PixelFormat format;
    float a, b, p;
    bool normal_map;
    int fast_cell;
};

void check_cpu_paths(const CpuPathCase& c, const MorphParams& params) {
    const bool is_float = c.format == PixelFormat::RgbaF32;
    const Layout base = random_layout(c.lines, 201);
    const RandomKeys random = random_keys(c.width, c.height, c.keys, c.format, params.normal_map, base, 210);
    const std::vector<KeyMap>& keys = random.keys;
    const Layout target = jitter(base, 0.04f, 230);
    std::vector<float> weights(c.keys, 1.0f / c.keys);
    const std::size_t values = static_cast<std::size_t>(c.width) * c.height * 4;

    struct Result {
        std::string kernels;
        std::vector<float> positions, pixels;
    };
    auto run = [&](const char* baseline) {
        ScopedEnv env("EMOFACE_MORPH_BASELINE", baseline);
        Result r;
        r.kernels = cpu_kernels_name();
        Morpher m(c.width, c.height, c.format, keys, Backend::Cpu);
        r.positions.resize(static_cast<std::size_t>(c.width) * c.height * c.keys * 2);
        m.positions_to_host(target, params, r.positions.data());
        r.pixels.resize(values);
        if (is_float) {
            m.morph_to_host(target, weights, params, r.pixels.data());
        } else {
            std::vector<std::uint8_t> out(values);
            m.morph_to_host(target, weights, params, out.data());
            for (std::size_t i = 0; i < values; ++i) r.pixels[i] = out[i];
        }
        return r;
    };
    const Result usual = run(nullptr), baseline = run("1");
    ASSERT_EQ(baseline.kernels, "baseline");
    ::testing::Test::RecordProperty("usual_kernels", usual.kernels);

    // FMA contraction and wider vectors only change the rounding.
    const double lsb = is_float ? 1e-4 : 1.0;
    EXPECT_LT(max_abs_diff(baseline.positions, usual.positions), 1e-3) << "pixels, against " << usual.kernels;
    EXPECT_LE(max_abs_diff(baseline.pixels, usual.pixels), lsb) << "against " << usual.kernels;
    if (params.accuracy == Accuracy::Exact) {
        std::vector<double> ref_pos;
        std::vector<Layout> layouts;
        for (const KeyMap& k : keys) layouts.push_back(k.layout);
        reference_positions(c.width, c.height, layouts, target, params, ref_pos);
        double worst = 0.0;
        for (std::size_t i = 0; i < ref_pos.size(); ++i)
            worst = std::fmax(worst, std::fabs(baseline.positions[i] - ref_pos[i]));
        EXPECT_LT(worst, 1e-3) << "pixels, baseline against the reference";
    }
}

class MorphCpuPathParity : public ::testing::TestWithParam<CpuPathCase> {};

// The key cases of the tests above (both weight laws, 1 to 8 sources, RGBA8
// and float, normal maps, exact and fast with both run lengths, crowded
// cells): the baseline loops agree with the usual ones, and with the double
// reference.
TEST_P(MorphCpuPathParity, BaselineAgreesWithTheUsualLoopsAndTheReference) {
    const CpuPathCase& c = GetParam();
    for (Accuracy accuracy : {Accuracy::Exact, Accuracy::Fast}) {
        SCOPED_TRACE(to_string(accuracy));
        MorphParams params;
        params.a = c.a;
        params.b = c.b;
        params.p = c.p;
        params.normal_map = c.normal_map;
        params.accuracy = accuracy;
        params.fast_cell = c.fast_cell;
        check_cpu_paths(c, params);
    }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, MorphCpuPathParity,
    ::testing::Values(CpuPathCase{"square_K1", 64, 64, 1, 12, PixelFormat::Rgba8, 0.01f, 2.0f, 0.5f, false, 8},
                      CpuPathCase{"wide_K3", 96, 40, 3, 10, PixelFormat::Rgba8, 0.01f, 2.0f, 0.5f, false, 4},
                      CpuPathCase{"tall_K2_b1p3", 36, 70, 2, 9, PixelFormat::Rgba8, 0.02f, 1.3f, 0.0f, false, 8},
                      CpuPathCase{"K8_p1", 32, 32, 8, 6, PixelFormat::Rgba8, 0.005f, 2.0f, 1.0f, false, 4},
                      CpuPathCase{"normals_K3", 40, 32, 3, 8, PixelFormat::Rgba8, 0.01f, 2.0f, 0.5f, true, 8},
                      CpuPathCase{"crowded_float_K2", 48, 48, 2, 40, PixelFormat::RgbaF32, 0.01f, 2.0f, 0.5f, false, 4}),
    [](const auto& info) { return std::string(info.param.name); });

// ---- rest value, many keys, regions ----------------------------------------------------
//
// out = Σ w_k key_k + (1 − Σ w) rest, a key being rest outside its region
// (morph.h). Keys of constant colour make the warp irrelevant where a test
// is about the blend.

std::vector<float> constant_map(int w, int h, std::array<float, 4> c) {
    std::vector<float> img(static_cast<std::size_t>(w) * h * 4);
    for (std::size_t i = 0; i < img.size(); ++i) img[i] = c[i % 4];
    return img;
}

// Morphs `keys` (RgbaF32 or Rgba8 pixels as given) and returns the output as
// floats in the format's units.
std::vector<float> morph_floats(int w, int h, PixelFormat format, const std::vector<KeyMap>& keys,
                                const Layout& target, const std::vector<float>& weights, const MorphParams& params) {
    Morpher m(w, h, format, keys, Backend::Cpu);
    std::vector<float> out(static_cast<std::size_t>(w) * h * 4);
    if (format == PixelFormat::RgbaF32) {
        m.morph_to_host(target, weights, params, out.data());
    } else {
        std::vector<std::uint8_t> bytes(out.size());
        m.morph_to_host(target, weights, params, bytes.data());
        for (std::size_t i = 0; i < out.size(); ++i) out[i] = bytes[i];
    }
    return out;
}

// Weights summing to 1: rest has no share, so the thesis's convex blend is
// the same to the last bit whatever rest is (and rest = 0 is the old path).
TEST(MorphRest, WeightsSummingToOneGiveTheConvexBlendBitForBit) {
    const int w = 40, h = 32;
    const Layout base = random_layout(6, 301), target = jitter(base, 0.04f, 302);
    for (PixelFormat format : {PixelFormat::Rgba8, PixelFormat::RgbaF32})
        for (bool normal_map : {false, true})
            for (Accuracy acc : {Accuracy::Exact, Accuracy::Fast}) {
                SCOPED_TRACE(std::string(to_string(format)) + (normal_map ? " normals " : " colour ") + to_string(acc));
                RandomKeys keys = random_keys(w, h, 3, format, normal_map, base, 303);
                MorphParams plain;
                plain.normal_map = normal_map;
                plain.accuracy = acc;
                MorphParams with_rest = plain;
                with_rest.rest = {0.5f, 0.5f, 1.0f, 1.0f};
                const std::vector<float> weights{0.2f, 0.3f, 0.5f};
                EXPECT_EQ(morph_floats(w, h, format, keys.keys, target, weights, plain),
                          morph_floats(w, h, format, keys.keys, target, weights, with_rest));
            }
}

TEST(MorphRest, OneKeyAtHalfWeightIsHalfwayToRest) {
    const int w = 24, h = 20;
    const auto img = to_float(random_rgba8(w, h, 311));
    const Layout l = random_layout(5, 312);
    MorphParams params;
    params.rest = {0.25f, 0.5f, 0.75f, 1.0f};
    for (Accuracy acc : {Accuracy::Exact, Accuracy::Fast}) {
        params.accuracy = acc;
        const std::vector<float> out = morph_floats(w, h, PixelFormat::RgbaF32, {key(img.data(), l)}, l, {0.5f}, params);
        std::vector<float> expected(img.size());
        for (std::size_t i = 0; i < img.size(); ++i) expected[i] = 0.5f * img[i] + 0.5f * params.rest[i % 4];
        EXPECT_LT(max_abs_diff(out, expected), 1e-6) << to_string(acc);
    }
    // Moved lines: the double reference follows the same formula (RGBA8, regions too).
    const auto bytes = random_rgba8(w, h, 313);
    KeyMap k = key(bytes.data(), l);
    k.region = {0.2f, 0.3f, 0.7f, 0.8f};
    const Layout target = jitter(l, 0.04f, 314);
    std::vector<std::uint8_t> ref(bytes.size());
    reference_morph(w, h, PixelFormat::Rgba8, {k}, target, {0.5f}, params, ref.data());
    params.accuracy = Accuracy::Exact;
    const std::vector<float> out = morph_floats(w, h, PixelFormat::Rgba8, {k}, target, {0.5f}, params);
    EXPECT_LE(max_abs_diff(out, std::vector<float>(ref.begin(), ref.end())), 1.0);
}

// Wrinkle keys over flat skin: the slopes (x, y of the decoded normal) of
// overlapping keys add, as height-field gradients do; z and the cavity
// alpha add their deviations from flat; the sum is clamped to the encoding's
// range before it is renormalised.
TEST(MorphRest, NormalMapKeysOverFlatSkinAddSlopesAndCavities) {
    const int w = 16, h = 12;
    const Layout l = random_layout(4, 321);
    const std::array<float, 4> flat{0.5f, 0.5f, 1.0f, 1.0f};
    auto encode = [](double x, double y, double a) {
        const double len = std::sqrt(x * x + y * y + 1.0);
        return std::array<float, 4>{static_cast<float>(0.5 + 0.5 * x / len), static_cast<float>(0.5 + 0.5 * y / len),
                                    static_cast<float>(0.5 + 0.5 / len), static_cast<float>(a)};
    };
    const std::array<float, 4> kx = encode(0.3, 0.0, 0.8), ky = encode(0.0, -0.2, 0.7);
    const auto mx = constant_map(w, h, kx), my = constant_map(w, h, ky);
    // What the blend must hold: flat + Σ w (key − flat), clamped to [0, 1],
    // then renormalised (alpha as is).
    auto expected = [&](double wx, double wy) {
        double c[4];
        for (int i = 0; i < 4; ++i)
            c[i] = std::clamp(flat[i] + wx * (kx[i] - flat[i]) + wy * (ky[i] - flat[i]), 0.0, 1.0);
        double n[3], len2 = 0.0;
        for (int i = 0; i < 3; ++i) {
            n[i] = 2.0 * c[i] - 1.0;
            len2 += n[i] * n[i];
        }
        std::array<double, 4> out;
        for (int i = 0; i < 3; ++i) out[i] = 0.5 + 0.5 * n[i] / std::sqrt(len2);
        out[3] = c[3];
        return out;
    };
    MorphParams params;
    params.normal_map = true;
    params.rest = flat;
    struct Case {
        const char* name;
        float wx, wy;
    };
    for (const Case& c : {Case{"one key", 1.0f, 0.0f}, Case{"two keys", 1.0f, 1.0f}, Case{"doubled", 2.0f, 0.0f},
                          Case{"partial", 0.6f, 0.9f}, Case{"clamped", 6.0f, 5.0f}}) {
        SCOPED_TRACE(c.name);
        const std::vector<float> out =
            morph_floats(w, h, PixelFormat::RgbaF32, {key(mx.data(), l), key(my.data(), l)}, jitter(l, 0.05f, 322),
                         {c.wx, c.wy}, params);
        const std::array<double, 4> e = expected(c.wx, c.wy);
        for (int ch = 0; ch < 4; ++ch) EXPECT_NEAR(out[ch], e[ch], 1e-5) << "channel " << ch;
        EXPECT_EQ(max_abs_diff(out, constant_map(w, h, {out[0], out[1], out[2], out[3]})), 0.0) << "not uniform";
    }
    // Two equal slopes: the decoded x/z ratio doubles (gradients add).
    const std::vector<float> two =
        morph_floats(w, h, PixelFormat::RgbaF32, {key(mx.data(), l), key(mx.data(), l)}, l, {1.0f, 1.0f}, params);
    const double one_ratio = (2.0 * kx[0] - 1.0) / (2.0 * kx[2] - 1.0);
    const double two_ratio = (2.0 * two[0] - 1.0) / (2.0 * two[2] - 1.0);
    EXPECT_GT(two_ratio, 1.9 * one_ratio);
    // The cavity channel: 1 + (0.8 − 1) + (0.7 − 1) = 0.5; clamped at 0 for 6 and 5.
    EXPECT_NEAR(expected(1.0, 1.0)[3], 0.5, 1e-6);
    EXPECT_EQ(expected(6.0, 5.0)[3], 0.0);
}

// A key at weight 0 costs nothing: it is neither warped nor sampled, so even
// NaN pixels leave the output exactly as without it.
TEST(MorphKeys, AKeyAtWeightZeroIsNeverRead) {
    const int w = 32, h = 24;
    const Layout base = random_layout(5, 331), target = jitter(base, 0.04f, 332);
    const auto a = to_float(random_rgba8(w, h, 333));
    const std::vector<float> garbage(a.size(), std::nanf(""));
    const Layout lg = jitter(base, 0.05f, 334);
    for (Accuracy acc : {Accuracy::Exact, Accuracy::Fast}) {
        MorphParams params;
        params.accuracy = acc;
        params.rest = {0.5f, 0.5f, 1.0f, 1.0f};
        for (float wa : {1.0f, 0.7f}) {
            const auto alone = morph_floats(w, h, PixelFormat::RgbaF32, {key(a.data(), base)}, target, {wa}, params);
            const auto with_nan = morph_floats(w, h, PixelFormat::RgbaF32,
                                               {key(garbage.data(), lg), key(a.data(), base), key(garbage.data(), lg)},
                                               target, {0.0f, wa, 0.0f}, params);
            EXPECT_EQ(alone, with_nan) << to_string(acc) << " weight " << wa;
        }
    }
}

// kMaxKeys keys, most of them at weight > 0 (three batches of sources), agree
// with the double reference.
TEST(MorphKeys, KMaxKeysBlendLikeTheReference) {
    const int w = 24, h = 20;
    const Layout base = random_layout(5, 341), target = jitter(base, 0.04f, 342);
    RandomKeys keys = random_keys(w, h, Morpher::kMaxKeys, PixelFormat::Rgba8, false, base, 343);
    std::vector<float> weights(Morpher::kMaxKeys, 0.0f);
    for (int k = 0; k < Morpher::kMaxKeys; ++k)
        if (k % 3 != 2) weights[k] = 0.045f;  // 22 keys, Σ = 0.99
    MorphParams params;
    params.rest = {0.2f, 0.4f, 0.6f, 0.8f};
    std::vector<std::uint8_t> ref(static_cast<std::size_t>(w) * h * 4);
    reference_morph(w, h, PixelFormat::Rgba8, keys.keys, target, weights, params, ref.data());
    const std::vector<float> ref_f(ref.begin(), ref.end());
    for (Accuracy acc : {Accuracy::Exact, Accuracy::Fast}) {
        params.accuracy = acc;
        params.fast_reach = 64.0f;  // every line near: fast is exact here
        EXPECT_LE(max_abs_diff(morph_floats(w, h, PixelFormat::Rgba8, keys.keys, target, weights, params), ref_f), 1.0)
            << to_string(acc);
    }
}

// Many region keys (batches of sources that differ from block to block) over
// a neutral key, weights summing to 7.6, normal maps over flat skin: the
// reference, which evaluates every key everywhere, agrees.
TEST(MorphKeys, ManyRegionKeysBlendLikeTheReference) {
    const int w = 56, h = 48;
    const Layout base = random_layout(6, 361), target = jitter(base, 0.04f, 362);
    RandomKeys keys = random_keys(w, h, 13, PixelFormat::Rgba8, true, base, 363);
    std::vector<float> weights(13, 0.0f);
    weights[0] = 1.0f;
    for (int k = 1; k < 13; ++k) {
        const float x0 = 0.05f + 0.06f * static_cast<float>(k), y0 = 0.7f - 0.05f * static_cast<float>(k);
        keys.keys[k].region = {x0, y0, x0 + 0.2f, y0 + 0.22f};
        if (k != 4 && k != 9) weights[k] = 0.66f;
    }
    MorphParams params;
    params.normal_map = true;
    params.rest = {128.0f / 255.0f, 128.0f / 255.0f, 1.0f, 1.0f};
    std::vector<std::uint8_t> ref(static_cast<std::size_t>(w) * h * 4);
    reference_morph(w, h, PixelFormat::Rgba8, keys.keys, target, weights, params, ref.data());
    const std::vector<float> ref_f(ref.begin(), ref.end());
    for (Accuracy acc : {Accuracy::Exact, Accuracy::Fast}) {
        params.accuracy = acc;
        params.fast_reach = 64.0f;  // every line near: fast is exact here
        params.fast_cell = 4;
        EXPECT_LE(max_abs_diff(morph_floats(w, h, PixelFormat::Rgba8, keys.keys, target, weights, params), ref_f), 1.0)
            << to_string(acc);
    }
}

// A key with a region is the same key over the whole map with rest outside
// the region, whatever its own pixels hold there, for targets that keep,
// jitter, move and scale the region, exact and fast.
struct RegionCase {
    const char* name;
    float dx, dy, scale, jitter;
};

class MorphRegion : public ::testing::TestWithParam<RegionCase> {};

TEST_P(MorphRegion, ARegionKeyIsTheWholeKeyWithRestOutsideItsRegion) {
    const RegionCase& c = GetParam();
    const int w = 80, h = 64;
    const Layout base = random_layout(7, 351);
    Layout target = jitter(base, c.jitter, 352);
    for (Line& l : target) {
        l = {0.5f + c.scale * (l.px - 0.5f) + c.dx, 0.5f + c.scale * (l.py - 0.5f) + c.dy,
             0.5f + c.scale * (l.qx - 0.5f) + c.dx, 0.5f + c.scale * (l.qy - 0.5f) + c.dy};
    }
    const Region region{0.3f, 0.25f, 0.55f, 0.5f};
    // Rest 128/255 (RGBA8 holds it exactly) over flat-ish keys.
    const std::array<float, 4> rest{128.0f / 255.0f, 128.0f / 255.0f, 1.0f, 1.0f};
    for (PixelFormat format : {PixelFormat::Rgba8, PixelFormat::RgbaF32}) {
        const auto neutral8 = random_rgba8(w, h, 353), wrinkle8 = random_rgba8(w, h, 354);
        auto whole8 = wrinkle8, garbage8 = wrinkle8;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const bool inside = x >= region.x0 * w && x < region.x1 * w && y >= region.y0 * h && y < region.y1 * h;
                for (int ch = 0; ch < 4; ++ch) {
                    const std::size_t i = (static_cast<std::size_t>(y) * w + x) * 4 + ch;
                    if (!inside) {
                        whole8[i] = static_cast<std::uint8_t>(std::lround(rest[ch] * 255.0f));
                        garbage8[i] = static_cast<std::uint8_t>(255 - (i % 7) * 30);
                    }
                }
            }
        const auto neutralf = to_float(neutral8), wholef = to_float(whole8), garbagef = to_float(garbage8);
        const bool f32 = format == PixelFormat::RgbaF32;
        KeyMap neutral = key(f32 ? static_cast<const void*>(neutralf.data()) : neutral8.data(), jitter(base, 0.03f, 355));
        KeyMap whole = key(f32 ? static_cast<const void*>(wholef.data()) : whole8.data(), base);
        KeyMap cropped = key(f32 ? static_cast<const void*>(garbagef.data()) : garbage8.data(), base);
        cropped.region = region;
        for (Accuracy acc : {Accuracy::Exact, Accuracy::Fast}) {
            for (bool normal_map : {false, true}) {
                SCOPED_TRACE(std::string(to_string(format)) + " " + to_string(acc) + (normal_map ? " normals" : ""));
                MorphParams params;
                params.accuracy = acc;
                params.rest = rest;
                params.normal_map = normal_map;
                const std::vector<float> weights{1.0f, 0.8f};
                const auto a = morph_floats(w, h, format, {neutral, whole}, target, weights, params);
                const auto b = morph_floats(w, h, format, {neutral, cropped}, target, weights, params);
                // Where the region key is left out, rest's share is added
                // to the last bit differently: rounding only.
                EXPECT_LE(max_abs_diff(a, b), f32 ? 1e-5 : 1.0);
                // ... and the wrinkle key does show (it is not simply dropped).
                const auto plain = morph_floats(w, h, format, {neutral, cropped}, target, {1.0f, 0.0f}, params);
                EXPECT_GT(max_abs_diff(b, plain), f32 ? 0.05 : 12.0);
            }
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Targets, MorphRegion,
                         ::testing::Values(RegionCase{"same_layout", 0.0f, 0.0f, 1.0f, 0.0f},
                                           RegionCase{"jittered", 0.0f, 0.0f, 1.0f, 0.03f},
                                           RegionCase{"moved", 0.2f, -0.15f, 1.0f, 0.01f},
                                           RegionCase{"scaled_and_moved", -0.1f, 0.1f, 1.3f, 0.02f},
                                           RegionCase{"shrunk", 0.05f, 0.0f, 0.7f, 0.02f}),
                         [](const auto& info) { return std::string(info.param.name); });

// ---- bad input -------------------------------------------------------------------------

struct BadInput {
    const char* name;
    std::function<void()> action;
    std::string message;  // the error must contain this
};

std::vector<BadInput> bad_inputs() {
    static const auto img = random_rgba8(16, 16, 141);
    static const Layout three = random_layout(3, 142);
    const void* px = img.data();
    auto morpher = [=] {
        return Morpher(16, 16, PixelFormat::Rgba8, {key(px, three), key(px, three)}, Backend::Cpu);
    };
    auto frame = [=](Layout target, std::vector<float> weights, MorphParams params = {}) {
        return [=] {
            Morpher m = morpher();
            std::vector<std::uint8_t> out(16 * 16 * 4);
            m.morph_to_host(target, weights, params, out.data());
        };
    };
    Layout zero_key = three;
    zero_key[1] = {0.5f, 0.5f, 0.5f, 0.5f};
    Layout nan_key = three;
    nan_key[2].px = std::nanf("");
    Layout inf_target = three;
    inf_target[2].qy = INFINITY;
    MorphParams a0;
    a0.a = 0.0f;
    MorphParams bneg;
    bneg.b = -1.0f;
    MorphParams cell5;
    cell5.accuracy = Accuracy::Fast;
    cell5.fast_cell = 5;
    KeyMap small = key(px, three);
    small.width = 8;
    small.height = 16;
    KeyMap flipped = key(px, three);
    flipped.region = {0.5f, 0.0f, 0.4f, 1.0f};
    KeyMap outside = key(px, three);
    outside.region = {0.0f, 0.0f, 1.5f, 1.0f};
    MorphParams nan_rest;
    nan_rest.rest[2] = std::nanf("");

    return {
        {"size zero", [=] { Morpher(0, 16, PixelFormat::Rgba8, {key(px, three)}, Backend::Cpu); },
         "morph: Morpher(): size 0 x 16, expected width and height in 1..16384"},
        {"size too large", [=] { Morpher(16, 20000, PixelFormat::Rgba8, {key(px, three)}, Backend::Cpu); },
         "morph: Morpher(): size 16 x 20000, expected width and height in 1..16384"},
        {"K = 0", [] { Morpher(16, 16, PixelFormat::Rgba8, {}, Backend::Cpu); },
         "morph: Morpher(): K = 0 key maps, expected 1 to 32"},
        {"K = kMaxKeys + 1",
         [=] {
             Morpher(16, 16, PixelFormat::Rgba8, std::vector<KeyMap>(Morpher::kMaxKeys + 1, key(px, three)),
                     Backend::Cpu);
         },
         "morph: Morpher(): K = 33 key maps, expected 1 to 32 (Morpher::kMaxKeys)"},
        {"region inside out", [=] { Morpher(16, 16, PixelFormat::Rgba8, {key(px, three), flipped}, Backend::Cpu); },
         "morph: Morpher(): key 1 region is (0.5, 0) - (0.4, 1), expected 0 <= x0 < x1 <= 1 and 0 <= y0 < y1 <= 1"},
        {"region past the map", [=] { Morpher(16, 16, PixelFormat::Rgba8, {outside}, Backend::Cpu); },
         "morph: Morpher(): key 0 region is (0, 0) - (1.5, 1), expected 0 <= x0 < x1 <= 1"},
        {"null pixels", [=] { Morpher(16, 16, PixelFormat::Rgba8, {key(px, three), key(nullptr, three)}, Backend::Cpu); },
         "morph: Morpher(): key 1 has no pixels (null pointer)"},
        {"sizes differ", [=] { Morpher(16, 16, PixelFormat::Rgba8, {key(px, three), small}, Backend::Cpu); },
         "morph: Morpher(): key 1 is 8 x 16, expected 16 x 16 (all key maps the same size)"},
        {"line counts differ",
         [=] { Morpher(16, 16, PixelFormat::Rgba8, {key(px, three), key(px, random_layout(2, 143))}, Backend::Cpu); },
         "morph: Morpher(): key 1 layout has 2 lines, key 0 has 3 (every layout needs the same line count)"},
        {"too many lines",
         [=] { Morpher(16, 16, PixelFormat::Rgba8, {key(px, random_layout(4097, 145))}, Backend::Cpu); },
         "morph: Morpher(): key 0 layout has 4097 lines, expected at most 4096"},
        {"zero-length key line", [=] { Morpher(16, 16, PixelFormat::Rgba8, {key(px, zero_key)}, Backend::Cpu); },
         "morph: Morpher(): key 0 line 1 has zero length: P = (0.5, 0.5), Q = (0.5, 0.5), expected P != Q"},
        {"NaN key coordinate",
         [=] { Morpher(16, 16, PixelFormat::Rgba8, {key(px, three), key(px, nan_key)}, Backend::Cpu); },
         "morph: Morpher(): key 1 line 2 has a non-finite coordinate: P = (nan,"},
        {"target line count", frame(random_layout(2, 144), {0.5f, 0.5f}),
         "morph: morph_to_host(): target layout has 2 lines, expected 3 (the key layouts' count)"},
        {"infinite target coordinate", frame(inf_target, {0.5f, 0.5f}),
         "morph: morph_to_host(): target line 2 has a non-finite coordinate"},
        {"weight count", frame(three, {1.0f}), "morph: morph_to_host(): 1 weights, expected 2 (one per key map)"},
        {"negative weight", frame(three, {0.5f, -0.25f}),
         "morph: morph_to_host(): weight 1 is -0.25, expected a finite value >= 0"},
        {"NaN weight", frame(three, {std::nanf(""), 0.5f}),
         "morph: morph_to_host(): weight 0 is nan, expected a finite value >= 0"},
        {"weights over kMaxKeys", frame(three, {20.0f, 13.0f}),
         "morph: morph_to_host(): weights sum to 33, expected at most 32 (kMaxKeys)"},
        {"NaN rest", frame(three, {0.5f, 0.5f}, nan_rest),
         "morph: morph_to_host(): params.rest[2] = nan, expected a finite value"},
        {"a = 0", frame(three, {0.5f, 0.5f}, a0), "morph: morph_to_host(): params.a = 0, expected a finite value > 0"},
        {"b < 0", frame(three, {0.5f, 0.5f}, bneg), "morph: morph_to_host(): params.b = -1, expected a value in [0, 16]"},
        {"fast cell", frame(three, {0.5f, 0.5f}, cell5),
         "morph: morph_to_host(): params.fast_cell = 5, expected 4, 8, 16 or 32"},
        {"null output",
         [=] {
             Morpher m = morpher();
             m.morph_to_host(three, {0.5f, 0.5f}, {}, nullptr);
         },
         "morph: morph_to_host(): out is null"},
        {"device output on the CPU backend",
         [=] {
             Morpher m = morpher();
             std::vector<std::uint8_t> out(16 * 16 * 4);
             m.morph_to_device(three, {0.5f, 0.5f}, {}, out.data(), 64);
         },
         "morph: morph_to_device(): this Morpher runs on the cpu backend, expected Backend::Cuda"},
        {"positions of a bad target",
         [=] {
             Morpher m = morpher();
             std::vector<float> out(16 * 16 * 4);
             m.positions_to_host(inf_target, {}, out.data());
         },
         "morph: positions_to_host(): target line 2 has a non-finite coordinate"},
    };
}

// A target line that collapses in some pose (a closed lid: upper and lower
// lid points meet) has no direction to warp along: it is skipped for that
// frame, which is the same as morphing without it.
TEST(MorphZeroLengthTarget, ACollapsedTargetLineIsSkippedForThatFrame) {
    const int w = 32, h = 24;
    const std::vector<std::uint8_t> a = random_rgba8(w, h, 7), b = random_rgba8(w, h, 8);
    const Layout la = random_layout(4, 21), lb = jitter(la, 0.03f, 22);
    Layout target = jitter(la, 0.02f, 23);
    target[2].qx = target[2].px;
    target[2].qy = target[2].py;
    const auto without_line_2 = [](Layout l) {
        l.erase(l.begin() + 2);
        return l;
    };
    Morpher all(w, h, PixelFormat::Rgba8, {key(a.data(), la), key(b.data(), lb)}, Backend::Cpu);
    Morpher three(w, h, PixelFormat::Rgba8,
                  {key(a.data(), without_line_2(la)), key(b.data(), without_line_2(lb))}, Backend::Cpu);
    std::vector<std::uint8_t> skipped(w * h * 4), reference(w * h * 4);
    all.morph_to_host(target, {0.6f, 0.4f}, {}, skipped.data());
    three.morph_to_host(without_line_2(target), {0.6f, 0.4f}, {}, reference.data());
    EXPECT_EQ(skipped, reference);
    // Every line collapsed: nothing moves, the keys are blended in place.
    Layout points = la;
    for (Line& l : points) l = {l.px, l.py, l.px, l.py};
    std::vector<float> positions(w * h * 2 * 2);
    all.positions_to_host(points, {}, positions.data());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int k = 0; k < 2; ++k) {
                EXPECT_FLOAT_EQ(positions[((y * w + x) * 2 + k) * 2 + 0], x + 0.5f);
                EXPECT_FLOAT_EQ(positions[((y * w + x) * 2 + k) * 2 + 1], y + 0.5f);
            }
}

TEST(MorphBadInput, EachBadInputIsAClearInputError) {
    for (const BadInput& c : bad_inputs()) {
        SCOPED_TRACE(c.name);
        try {
            c.action();
            ADD_FAILURE() << "no error";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(c.message), std::string::npos)
                << "got:      " << e.what() << "\nexpected: " << c.message;
        }
    }
}

TEST(MorphBadInput, ABadFrameLeavesTheMorpherUsable) {
    const auto img = random_rgba8(16, 16, 151);
    const Layout l = random_layout(3, 152);
    Morpher m(16, 16, PixelFormat::Rgba8, {key(img.data(), l)}, Backend::Cpu);
    std::vector<std::uint8_t> out(img.size());
    EXPECT_THROW(m.morph_to_host(l, {40.0f}, {}, out.data()), InputError);
    m.morph_to_host(l, {1.0f}, {}, out.data());
    EXPECT_EQ(max_abs_diff(out, img), 0.0);
}

}  // namespace
}  // namespace emoface::morph
