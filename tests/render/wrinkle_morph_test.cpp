// The morph result reaching the wrinkle texture: on the CPU by upload, on the
// GPU through CUDA-GL interop. Either way the texture must hold exactly what
// the CPU morph writes to host memory (interop: within the CPU/GPU parity of
// the morph itself).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "emoface/common/error.h"
#include "emoface/expression/face_state.h"
#include "emoface/fap/fap_io.h"
#include "emoface/morph/morph.h"
#include "emoface/render/face_assets.h"
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

// ---------------------------------------------------------------- keys by AU

namespace expression = emoface::expression;

std::vector<WrinkleKey> named_keys(std::initializer_list<const char*> names) {
    std::vector<WrinkleKey> keys;
    for (const char* n : names) keys.push_back({n, {}, {}, {}});
    return keys;
}

float weight_of(const std::vector<WrinkleKey>& keys, const std::vector<float>& w, const std::string& name) {
    for (std::size_t k = 0; k < keys.size(); ++k)
        if (keys[k].name == name) return w[k];
    ADD_FAILURE() << "no key " << name;
    return -1.0f;
}

const expression::EmotionProfiles& profiles() {
    static const expression::EmotionProfiles p =
        expression::load_emotion_profiles(std::string(EMOFACE_DATA_DIR) + "/expression/emotions.json");
    return p;
}

expression::FaceState mix_state(const char* mix) {
    return expression::face_state(expression::parse_emotion_mix(mix), profiles());
}

// A key's weight is what drives it: an AU key its side's intensity, an
// emotion key the mix's weight, neutral what the emotion keys leave.
TEST(KeyWeights, EachKeyIsWeightedByWhatItIsNamedFor) {
    const auto keys = named_keys({"neutral", "AU12L", "AU12R", "AU6L", "AU6R", "AU1L", "AU17", "joy", "anger"});
    const expression::FaceState smile = mix_state("0.7 AU12L + 0.2 AU12R");
    const std::vector<float> w = key_weights(keys, smile);
    EXPECT_FLOAT_EQ(weight_of(keys, w, "AU12L"), 0.7f);
    EXPECT_FLOAT_EQ(weight_of(keys, w, "AU12R"), 0.2f);
    // Keys nothing drives weigh exactly 0, so the morph skips them.
    for (const char* off : {"AU6L", "AU6R", "AU1L", "AU17", "anger"}) EXPECT_EQ(weight_of(keys, w, off), 0.0f) << off;
    // Neutral gives up only what the emotion keys take.
    EXPECT_FLOAT_EQ(weight_of(keys, w, "neutral"), 1.0f - weight_of(keys, w, "joy"));

    // AU keys alone: neutral stays 1, the AUs add their wrinkles to it.
    const auto au_keys = named_keys({"neutral", "AU6L", "AU6R", "AU12L", "AU12R", "AU4L"});
    const std::vector<float> joy = key_weights(au_keys, mix_state("joy"));
    const expression::AuIntensities& joy_aus = profiles().prototypes[expression::emotion_index(expression::Emotion::Joy)];
    EXPECT_GT(joy_aus.left[12], 0.5);
    EXPECT_EQ(joy, (std::vector<float>{1.0f, float(joy_aus.left[6]), float(joy_aus.right[6]), float(joy_aus.left[12]),
                                       float(joy_aus.right[12]), 0.0f}));
    // The thesis's seven emotion keys: a convex blend, as before.
    const auto emotion_keys = named_keys({"neutral", "joy", "sadness", "anger", "fear", "disgust", "surprise"});
    const std::vector<float> mix = key_weights(emotion_keys, mix_state("0.6 anger + 0.3 fear"));
    const std::vector<float> expected = {0.1f, 0.0f, 0.0f, 0.6f, 0.3f, 0.0f, 0.0f};
    for (std::size_t k = 0; k < expected.size(); ++k) EXPECT_NEAR(mix[k], expected[k], 1e-6f) << emotion_keys[k].name;
}

TEST(KeyWeights, NamesThatDriveNothingAreRejected) {
    EXPECT_TRUE(key_driver("AU6L"));
    EXPECT_TRUE(key_driver("surprise"));
    EXPECT_FALSE(key_driver("happy"));
    EXPECT_FALSE(key_driver("AU6X"));
    EXPECT_THROW(key_weights(named_keys({"neutral", "forehead"}), mix_state("joy")), emoface::InputError);
}

// Playing Xface's smile weights the crow's feet and the nasolabial folds,
// not forehead worry lines.
TEST(KeyWeights, XfaceJoyWeightsSmileKeysAboveForeheadKeys) {
    const std::filesystem::path path = std::filesystem::path(EMOFACE_REALDATA_DIR) / "fap" / "xface_joy.fap";
    if (!std::filesystem::exists(path))
        GTEST_SKIP() << path << " is absent (set EMOFACE_REALDATA_DIR to the folder holding fap/xface_joy.fap)";
    const auto stream = emoface::fap::resolve_untransmitted(emoface::fap::read_fap_file(path.string()));
    ASSERT_GT(stream.frames.size(), 40u);
    const auto keys = named_keys({"neutral", "AU1L", "AU1R", "AU2L", "AU2R", "AU4L", "AU4R", "AU6L", "AU6R",
                                  "AU12L", "AU12R"});
    const std::vector<float> w = key_weights(keys, expression::face_state(stream.frames[40], profiles()));
    float smile = 0.0f, forehead = 0.0f;
    for (const char* k : {"AU6L", "AU6R", "AU12L", "AU12R"}) smile = std::min(smile == 0.0f ? 1.0f : smile, weight_of(keys, w, k));
    for (const char* k : {"AU1L", "AU1R", "AU2L", "AU2R", "AU4L", "AU4R"}) forehead = std::max(forehead, weight_of(keys, w, k));
    std::printf("xface_joy frame 40: weakest smile key %.2f, strongest forehead key %.2f\n", smile, forehead);
    EXPECT_GT(smile, 0.2f);
    EXPECT_GT(smile, 2.0f * forehead);
}

// The generated AU keys through a FaceScene: a left-only smile wrinkles only
// the face's left nasolabial fold in the texture the skin is drawn with.
class AuKeys : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        FaceAssetsOptions ao;
        ao.wrinkle_map_size = 256;
        ao.face.resolution_scale = 0.5;
        assets_ = load_default_face_assets(EMOFACE_DATA_DIR, ao);
        PlatformOptions po;
        po.width = po.height = 16;
        platform_ = std::make_unique<HeadlessPlatform>(po);
        FaceSceneOptions so;
        so.backend = morph::Backend::Cpu;
        scene_ = make_face_scene(*platform_, *assets_, so);
    }
    static void TearDownTestSuite() {
        scene_.reset();
        platform_.reset();
        assets_.reset();
    }
    // The wrinkle texture of `mix`, and the mean tilt |n.x| + |n.y| in a box
    // round the nasolabial fold of each side (at the frame's layout).
    static std::pair<float, float> nasolabial_tilts(const char* mix) {
        const expression::FaceState state = mix_state(mix);
        scene_->update(state.faps, key_weights(assets_->keys, state));
        std::vector<std::uint8_t> tex(std::size_t(256) * 256 * 4);
        scene_->wrinkle_texture().download(tex.data());
        const expression::FeatureLayout& l = scene_->layout();
        const float u = l.face_unit();
        const auto tilt = [&](glm::vec2 a, glm::vec2 b) {
            const glm::vec2 lo = glm::min(a, b), hi = glm::max(a, b);
            double sum = 0;
            int n = 0;
            for (int y = int(lo.y * 256); y < int(hi.y * 256); ++y)
                for (int x = int(lo.x * 256); x < int(hi.x * 256); ++x, ++n) {
                    const std::uint8_t* p = &tex[(std::size_t(y) * 256 + x) * 4];
                    sum += std::abs(p[0] - 128) + std::abs(p[1] - 128);
                }
            return float(sum / std::max(n, 1) / 127.5);
        };
        return {tilt(l.at("9.1"), l.at("8.3") + u * glm::vec2(0.22f, 0.05f)),
                tilt(l.at("9.2"), l.at("8.4") + u * glm::vec2(-0.22f, 0.05f))};
    }
    static std::unique_ptr<FaceAssets> assets_;
    static std::unique_ptr<HeadlessPlatform> platform_;
    static std::unique_ptr<FaceScene> scene_;
};
std::unique_ptr<FaceAssets> AuKeys::assets_;
std::unique_ptr<HeadlessPlatform> AuKeys::platform_;
std::unique_ptr<FaceScene> AuKeys::scene_;

TEST_F(AuKeys, OneKeyPerWrinklingAuSideAndNeutral) {
    std::vector<std::string> names;
    for (const WrinkleKey& k : assets_->keys) names.push_back(k.name);
    ASSERT_FALSE(names.empty());
    EXPECT_EQ(names.front(), "neutral");
    for (const char* n : {"AU1L", "AU1R", "AU2L", "AU4R", "AU6L", "AU6R", "AU9L", "AU12L", "AU12R", "AU15L", "AU17"})
        EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
    EXPECT_LE(assets_->keys.size(), std::size_t(morph::Morpher::kMaxKeys));
    // Small keys cost their region only: no AU key covers half the map.
    for (const WrinkleKey& k : assets_->keys) {
        if (k.name == "neutral") continue;
        const glm::vec2 size = k.region.max - k.region.min;
        EXPECT_LT(size.x * size.y, 0.5f) << k.name;
        EXPECT_FALSE(k.region.empty()) << k.name;
    }
}

TEST_F(AuKeys, AOneSidedSmileWrinklesOneSide) {
    const auto [left, right] = nasolabial_tilts("AU12L");
    const auto [both_l, both_r] = nasolabial_tilts("AU12");
    const auto [none_l, none_r] = nasolabial_tilts("neutral");
    std::printf("nasolabial tilt: AU12L %.4f | %.4f, AU12 %.4f | %.4f, neutral %.4f | %.4f\n", left, right, both_l,
                both_r, none_l, none_r);
    EXPECT_GT(left, 3.0f * right);
    EXPECT_LT(right, none_r + 0.01f);
    EXPECT_GT(both_r, 3.0f * none_r);
}

}  // namespace

