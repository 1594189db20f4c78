// The morph result reaching the wrinkle texture: on the CPU by upload, on the
// GPU through CUDA-GL interop. Either way the texture must hold exactly what
// the CPU morph writes to host memory (interop: within the CPU/GPU parity of
// the morph itself).
#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "emoface/common/error.h"
#include "emoface/morph/morph.h"
#include "emoface/render/platform.h"
#include "emoface/render/wrinkle_morph.h"
#include "emoface/render/wrinkle_texture.h"
#include "support/parity.h"

namespace {

using namespace emoface::render;
namespace morph = emoface::morph;

constexpr int kW = 96, kH = 64, kKeys = 3, kLines = 6;

morph::Layout layout(unsigned seed, float jitter) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> pos(0.15f, 0.85f), d(-jitter, jitter);
    morph::Layout base;
    std::mt19937 base_rng(7);
    for (int i = 0; i < kLines; ++i) {
        const float x = 0.15f + 0.7f * float(i) / kLines, y = 0.2f + 0.1f * float(i % 3);
        base.push_back({x, y, x + 0.08f, y + 0.3f});
    }
    for (auto& l : base) {
        l.px += d(rng); l.py += d(rng); l.qx += d(rng); l.qy += d(rng);
    }
    return base;
}

// Normal maps with stripes and bumps, encoded 0.5 + 0.5 n.
std::vector<float> key_normals(int k) {
    std::vector<float> img(std::size_t(kW) * kH * 4);
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            const float a = std::sin(0.3f * float(x + 5 * k)) * 0.6f;
            const float b = std::cos(0.2f * float(y * (k + 1))) * 0.4f;
            const float len = std::sqrt(a * a + b * b + 1.0f);
            float* p = &img[(std::size_t(y) * kW + x) * 4];
            p[0] = 0.5f + 0.5f * a / len; p[1] = 0.5f + 0.5f * b / len;
            p[2] = 0.5f + 0.5f / len; p[3] = 1.0f;
        }
    return img;
}

std::vector<std::uint8_t> to_bytes(const std::vector<float>& f) {
    std::vector<std::uint8_t> out(f.size());
    for (std::size_t i = 0; i < f.size(); ++i) out[i] = std::uint8_t(std::lround(f[i] * 255.0f));
    return out;
}

struct Keys {
    std::vector<std::vector<float>> floats;
    std::vector<std::vector<std::uint8_t>> bytes;
    Keys() {
        for (int k = 0; k < kKeys; ++k) {
            floats.push_back(key_normals(k));
            bytes.push_back(to_bytes(floats.back()));
        }
    }
    std::vector<morph::KeyMap> maps(morph::PixelFormat f) const {
        std::vector<morph::KeyMap> m;
        for (int k = 0; k < kKeys; ++k)
            m.push_back({f == morph::PixelFormat::Rgba8 ? static_cast<const void*>(bytes[k].data())
                                                        : static_cast<const void*>(floats[k].data()),
                         layout(100 + k, 0.05f), kW, kH});
        return m;
    }
};

const std::vector<float> kWeights = {0.2f, 0.5f, 0.3f};

morph::MorphParams params() {
    morph::MorphParams p;
    p.normal_map = true;
    return p;
}

TexelFormat texel(morph::PixelFormat f) {
    return f == morph::PixelFormat::Rgba8 ? TexelFormat::RGBA8 : TexelFormat::RGBA32F;
}

// The texture's contents after one WrinkleMorph::update on `backend`, and the
// CPU morph's host output for the same frame.
template <typename T>
void morph_both_ways(Platform& platform, morph::PixelFormat format, morph::Backend backend,
                     std::vector<T>& in_texture, std::vector<T>& on_host, bool& interop) {
    platform.make_current();
    const Keys keys;
    morph::Morpher gpu_or_cpu(kW, kH, format, keys.maps(format), backend);
    morph::Morpher cpu(kW, kH, format, keys.maps(format), morph::Backend::Cpu);
    WrinkleTexture texture(kW, kH, texel(format), NormalEncoding::Unsigned);
    WrinkleMorph wm(gpu_or_cpu, texture);
    interop = wm.uses_interop();
    const morph::Layout target = layout(1, 0.03f);
    wm.update(target, kWeights, params());
    const std::size_t n = std::size_t(kW) * kH * 4;
    in_texture.assign(n, T(0));
    texture.download(in_texture.data());
    on_host.assign(n, T(0));
    cpu.morph_to_host(target, kWeights, params(), on_host.data());
}

class WrinkleMorphTest : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        PlatformOptions o;
        o.width = o.height = 16;
        o.cuda_device = 0;  // the EGL device that is CUDA device 0, when there is one
        platform_ = std::make_unique<HeadlessPlatform>(o);
    }
    static void TearDownTestSuite() { platform_.reset(); }
    static std::unique_ptr<HeadlessPlatform> platform_;
};
std::unique_ptr<HeadlessPlatform> WrinkleMorphTest::platform_;

TEST_F(WrinkleMorphTest, CpuUploadHoldsExactlyTheHostMorph8Bit) {
    std::vector<std::uint8_t> tex, host;
    bool interop = true;
    morph_both_ways(*platform_, morph::PixelFormat::Rgba8, morph::Backend::Cpu, tex, host, interop);
    EXPECT_FALSE(interop);
    EXPECT_EQ(tex, host);
    // Not the flat map the texture starts with.
    int flat = 0;
    for (std::size_t i = 0; i < tex.size(); i += 4) flat += tex[i] == 128 && tex[i + 1] == 128;
    EXPECT_LT(flat, kW * kH / 4);
}

TEST_F(WrinkleMorphTest, CpuUploadHoldsExactlyTheHostMorphFloat) {
    std::vector<float> tex, host;
    bool interop = true;
    morph_both_ways(*platform_, morph::PixelFormat::RgbaF32, morph::Backend::Cpu, tex, host,
                    interop);
    EXPECT_EQ(tex, host);
}

// The CUDA morph written straight into the GL texture against the CPU morph
// on the host, for one pixel format; skips where CUDA cannot share the
// context's textures.
template <class T>
void expect_interop_matches_the_cpu_morph(Platform& platform, morph::PixelFormat format, double tolerance) {
    if (!morph::cuda_available() || !cuda_interop_available())
        GTEST_SKIP() << "no CUDA device: " << morph::cuda_device_description();
    if (platform.is_software())
        GTEST_SKIP() << "the GL context is not on the GPU (" << platform.description()
                     << "): CUDA cannot share its textures";
    std::vector<T> tex, host;
    bool interop = false;
    morph_both_ways(platform, format, morph::Backend::Cuda, tex, host, interop);
    EXPECT_TRUE(interop);
    EXPECT_LE(emoface::testing::max_abs_diff(tex, host), tolerance);
}

TEST_F(WrinkleMorphTest, InteropMatchesTheCpuMorph8Bit) {
    // CPU and GPU morphs agree within one 8-bit step.
    expect_interop_matches_the_cpu_morph<std::uint8_t>(*platform_, morph::PixelFormat::Rgba8, 1.0);
}

TEST_F(WrinkleMorphTest, InteropMatchesTheCpuMorphFloat) {
    expect_interop_matches_the_cpu_morph<float>(*platform_, morph::PixelFormat::RgbaF32, 1e-4);
}

TEST_F(WrinkleMorphTest, MismatchedTextureIsAnError) {
    platform_->make_current();
    const Keys keys;
    morph::Morpher m(kW, kH, morph::PixelFormat::Rgba8, keys.maps(morph::PixelFormat::Rgba8),
                     morph::Backend::Cpu);
    WrinkleTexture wrong_size(kW / 2, kH, TexelFormat::RGBA8, NormalEncoding::Unsigned);
    WrinkleTexture wrong_format(kW, kH, TexelFormat::RGBA32F, NormalEncoding::Unsigned);
    try {
        WrinkleMorph wm(m, wrong_size);
        FAIL() << "accepted a texture of the wrong size";
    } catch (const emoface::Error& e) {
        EXPECT_STREQ(e.what(), "render: WrinkleMorph: the morph is 96x64, the texture 48x64");
    }
    EXPECT_THROW(WrinkleMorph(m, wrong_format), emoface::Error);
}

TEST_F(WrinkleMorphTest, UploadChecksThePitch) {
    platform_->make_current();
    WrinkleTexture t(8, 4, TexelFormat::RGBA8, NormalEncoding::Unsigned);
    std::vector<std::uint8_t> px(64 * 4, 7);
    EXPECT_THROW(t.upload(px.data(), 8), emoface::Error);   // shorter than a row
    EXPECT_THROW(t.upload(px.data(), 34), emoface::Error);  // not whole texels
    EXPECT_THROW(t.upload(nullptr), emoface::Error);
    t.upload(px.data(), 64);  // padded rows
    std::vector<std::uint8_t> back(8 * 4 * 4);
    t.download(back.data());
    EXPECT_EQ(back, std::vector<std::uint8_t>(back.size(), 7));
    EXPECT_THROW(WrinkleTexture(8, 4, TexelFormat::RGBA8, NormalEncoding::Signed), emoface::Error);
}

}  // namespace
