// morph on the CUDA backend against the CPU backend. Every test skips with a
// message where no CUDA device is usable (CI); they run on the GPU machine.
#include <cuda_runtime.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "emoface/common/error.h"
#include "emoface/morph/morph.h"
#include "morph_test_util.h"

namespace emoface::morph {
namespace {

using namespace test;

#define SKIP_WITHOUT_CUDA()                                                                    \
    if (!cuda_available())                                                                     \
    GTEST_SKIP() << "no usable CUDA device (" << cuda_device_description()                      \
                 << "): the CUDA backend is tested on the GPU machine"

#define CUDA_OK(call) ASSERT_EQ((call), cudaSuccess) << #call

struct ParityCase {
    const char* name;
    int width, height, keys, lines;
    PixelFormat format;
    bool normal_map;
    float b;
    Accuracy accuracy;
    int zero_weight;  // index of a key given weight 0, or -1
};

// What the CPU and CUDA backends each produced for one case.
struct Outputs {
    std::vector<std::uint8_t> bytes;
    std::vector<float> floats;
    std::vector<float> positions;
};

class MorphCudaParity : public ::testing::TestWithParam<ParityCase> {};

TEST_P(MorphCudaParity, CudaAgreesWithTheCpu) {
    SKIP_WITHOUT_CUDA();
    const ParityCase& c = GetParam();
    const Layout base = random_layout(c.lines, 7);
    const RandomKeys random = random_keys(c.width, c.height, c.keys, c.format, c.normal_map, base, 10);
    const std::vector<KeyMap>& keys = random.keys;
    const Layout target = jitter(base, 0.04f, 30);
    std::vector<float> weights(c.keys, 0.0f);
    const int nonzero = c.keys - (c.zero_weight >= 0 ? 1 : 0);
    for (int k = 0; k < c.keys; ++k)
        if (k != c.zero_weight) weights[k] = 1.0f / nonzero;
    MorphParams params;
    params.b = c.b;
    params.normal_map = c.normal_map;
    params.accuracy = c.accuracy;

    Outputs out[2];
    const Backend backends[2] = {Backend::Cpu, Backend::Cuda};
    const std::size_t pixels = static_cast<std::size_t>(c.width) * c.height;
    for (int i = 0; i < 2; ++i) {
        Morpher m(c.width, c.height, c.format, keys, backends[i]);
        ASSERT_EQ(m.backend(), backends[i]);
        out[i].positions.resize(pixels * c.keys * 2);
        m.positions_to_host(target, params, out[i].positions.data());
        if (c.format == PixelFormat::Rgba8) {
            out[i].bytes.assign(pixels * 4, 0xCD);  // poisoned: every pixel must be written
            m.morph_to_host(target, weights, params, out[i].bytes.data());
        } else {
            out[i].floats.assign(pixels * 4, -7.0f);
            m.morph_to_host(target, weights, params, out[i].floats.data());
        }
    }
    EXPECT_LT(max_abs_diff(out[0].positions, out[1].positions), 1e-3) << "pixels";
    // Exact mode samples by hand on both sides: within rounding. Fast mode
    // samples through the texture unit, whose bilinear weights have 8
    // fractional bits: up to half an LSB more, so 2 LSB.
    const double lsb = c.accuracy == Accuracy::Exact ? 1.0 : 2.0;
    if (c.format == PixelFormat::Rgba8)
        EXPECT_LE(max_abs_diff(out[0].bytes, out[1].bytes), lsb) << "LSB";
    else
        EXPECT_LE(max_abs_diff(out[0].floats, out[1].floats), lsb / 255.0);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, MorphCudaParity,
    ::testing::Values(
        // small images take one point a thread, N*K small enough for the by-value table
        ParityCase{"exact_K2_N20", 96, 80, 2, 20, PixelFormat::Rgba8, false, 2.0f, Accuracy::Exact, -1},
        ParityCase{"exact_K1_power", 64, 50, 1, 12, PixelFormat::Rgba8, false, 1.3f, Accuracy::Exact, -1},
        ParityCase{"exact_float_normals_K3", 70, 64, 3, 16, PixelFormat::RgbaF32, true, 2.0f, Accuracy::Exact, -1},
        ParityCase{"exact_normals_rgba8_K3", 70, 64, 3, 16, PixelFormat::Rgba8, true, 2.0f, Accuracy::Exact, -1},
        // K = 7, N = 100: the table goes through the device copy
        ParityCase{"exact_K7_N100_zero_weight", 128, 96, 7, 100, PixelFormat::Rgba8, false, 2.0f, Accuracy::Exact, 3},
        // K = 8, N = 200: 45 KB of lines, staged in two shared-memory chunks
        ParityCase{"exact_K8_N200", 64, 64, 8, 200, PixelFormat::Rgba8, false, 2.0f, Accuracy::Exact, -1},
        // over a million pixels: four points a thread
        ParityCase{"exact_1024_K2_N24", 1024, 1040, 2, 24, PixelFormat::Rgba8, false, 2.0f, Accuracy::Exact, -1},
        ParityCase{"fast_K2_N20", 100, 84, 2, 20, PixelFormat::Rgba8, false, 2.0f, Accuracy::Fast, -1},
        ParityCase{"fast_K7_N100_float", 128, 128, 7, 100, PixelFormat::RgbaF32, false, 2.0f, Accuracy::Fast, -1},
        ParityCase{"fast_normals_K3", 96, 64, 3, 30, PixelFormat::Rgba8, true, 2.0f, Accuracy::Fast, -1},
        ParityCase{"fast_1024_K7_N40", 1024, 1024, 7, 40, PixelFormat::Rgba8, false, 2.0f, Accuracy::Fast, -1},
        ParityCase{"fast_power_K2", 200, 120, 2, 25, PixelFormat::Rgba8, false, 1.5f, Accuracy::Fast, -1},
        // no lines: a plain blend
        ParityCase{"exact_K2_N0", 64, 48, 2, 0, PixelFormat::Rgba8, false, 2.0f, Accuracy::Exact, -1},
        ParityCase{"fast_K2_N0", 64, 48, 2, 0, PixelFormat::Rgba8, false, 2.0f, Accuracy::Fast, -1}),
    [](const auto& info) { return std::string(info.param.name); });

// Rest value, many keys and region keys (morph.h): the CUDA backend against
// the CPU, which tests/morph/morph_test.cpp holds to the formula.
struct RestCase {
    const char* name;
    int keys;         // all of them region keys but key 0 when `regions`
    int weighted;     // keys 0 .. weighted-1 at weight `weight` each
    float weight;
    bool regions;
    PixelFormat format;
    Accuracy accuracy;
};

class MorphCudaRest : public ::testing::TestWithParam<RestCase> {};

TEST_P(MorphCudaRest, CudaAgreesWithTheCpu) {
    SKIP_WITHOUT_CUDA();
    const RestCase& c = GetParam();
    const int w = 160, h = 128;
    const Layout base = random_layout(24, 41);
    RandomKeys random = random_keys(w, h, c.keys, c.format, true, base, 42);
    if (c.regions)
        for (int k = 1; k < c.keys; ++k) {  // ~6% of the map each, spread over it
            const float x0 = 0.05f + 0.7f * static_cast<float>((k * 37) % 19) / 19.0f;
            const float y0 = 0.05f + 0.7f * static_cast<float>((k * 23) % 17) / 17.0f;
            random.keys[k].region = {x0, y0, x0 + 0.25f, y0 + 0.25f};
        }
    std::vector<float> weights(c.keys, 0.0f);
    for (int k = 0; k < c.weighted; ++k) weights[k] = c.weight;
    weights[0] = 1.0f;
    MorphParams params;
    params.normal_map = true;
    params.rest = {0.5f, 0.5f, 1.0f, 1.0f};
    params.accuracy = c.accuracy;
    const Layout target = jitter(base, 0.04f, 43);
    const std::size_t n = static_cast<std::size_t>(w) * h * 4;
    std::vector<std::uint8_t> bytes[2];
    std::vector<float> floats[2];
    const Backend backends[2] = {Backend::Cpu, Backend::Cuda};
    for (int i = 0; i < 2; ++i) {
        Morpher m(w, h, c.format, random.keys, backends[i]);
        if (c.format == PixelFormat::Rgba8) {
            bytes[i].assign(n, 0xCD);
            m.morph_to_host(target, weights, params, bytes[i].data());
        } else {
            floats[i].assign(n, -7.0f);
            m.morph_to_host(target, weights, params, floats[i].data());
        }
    }
    const double lsb = c.accuracy == Accuracy::Exact ? 1.0 : 2.0;
    if (c.format == PixelFormat::Rgba8)
        EXPECT_LE(max_abs_diff(bytes[0], bytes[1]), lsb) << "LSB";
    else
        EXPECT_LE(max_abs_diff(floats[0], floats[1]), lsb / 255.0);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, MorphCudaRest,
    ::testing::Values(
        RestCase{"half_weight_one_key", 1, 1, 0.5f, false, PixelFormat::RgbaF32, Accuracy::Exact},
        RestCase{"k32_22_weighted_exact", 32, 22, 0.3f, false, PixelFormat::Rgba8, Accuracy::Exact},
        RestCase{"k32_22_weighted_fast", 32, 22, 0.3f, false, PixelFormat::RgbaF32, Accuracy::Fast},
        RestCase{"regions_21_keys_4_weighted_exact", 21, 5, 1.0f, true, PixelFormat::Rgba8, Accuracy::Exact},
        RestCase{"regions_21_keys_4_weighted_fast", 21, 5, 1.0f, true, PixelFormat::Rgba8, Accuracy::Fast},
        RestCase{"regions_32_keys_all_weighted_fast", 32, 32, 0.8f, true, PixelFormat::RgbaF32, Accuracy::Fast}),
    [](const auto& info) { return std::string(info.param.name); });

// A key at weight 0 is not read on the GPU either: NaN pixels change nothing.
TEST(MorphCuda, AKeyAtWeightZeroIsNeverRead) {
    SKIP_WITHOUT_CUDA();
    const int w = 64, h = 48;
    const Layout base = random_layout(6, 51), target = jitter(base, 0.04f, 52);
    const auto a = to_float(random_rgba8(w, h, 53));
    const std::vector<float> garbage(a.size(), std::nanf(""));
    KeyMap ka, kg;
    ka.pixels = a.data();
    ka.layout = base;
    kg.pixels = garbage.data();
    kg.layout = jitter(base, 0.05f, 54);
    for (Accuracy acc : {Accuracy::Exact, Accuracy::Fast}) {
        MorphParams params;
        params.accuracy = acc;
        std::vector<float> alone(a.size()), with_nan(a.size());
        Morpher(w, h, PixelFormat::RgbaF32, {ka}, Backend::Cuda).morph_to_host(target, {1.0f}, params, alone.data());
        Morpher(w, h, PixelFormat::RgbaF32, {kg, ka, kg}, Backend::Cuda)
            .morph_to_host(target, {0.0f, 1.0f, 0.0f}, params, with_nan.data());
        EXPECT_EQ(alone, with_nan) << to_string(acc);
    }
}

KeyMap key(const void* pixels, Layout layout) {
    KeyMap k;
    k.pixels = pixels;
    k.layout = std::move(layout);
    return k;
}

TEST(MorphCuda, IdentityGivesTheSourceBack) {
    SKIP_WITHOUT_CUDA();
    const int w = 77, h = 45;
    const auto img = random_rgba8(w, h, 41);
    const Layout l = random_layout(9, 42);
    Morpher m(w, h, PixelFormat::Rgba8, {key(img.data(), l)}, Backend::Cuda);
    std::vector<std::uint8_t> out(img.size());
    m.morph_to_host(l, {1.0f}, {}, out.data());
    EXPECT_EQ(max_abs_diff(out, img), 0.0);
}

TEST(MorphCuda, AutoPicksTheDevice) {
    SKIP_WITHOUT_CUDA();
    const auto img = random_rgba8(8, 8, 43);
    Morpher m(8, 8, PixelFormat::Rgba8, {key(img.data(), random_layout(2, 44))});
    EXPECT_EQ(m.backend(), Backend::Cuda);
    EXPECT_NE(m.cuda_stream(), nullptr);
}

// Device and surface outputs hold what the host output holds; frames queued
// back to back without waiting (the line table's staging buffer reused while
// earlier copies may be in flight) each get their own target.
TEST(MorphCuda, DeviceAndSurfaceOutputsMatchHostOutput) {
    SKIP_WITHOUT_CUDA();
    const int w = 130, h = 70;
    const auto a = random_rgba8(w, h, 51), b = random_rgba8(w, h, 52);
    const Layout base = random_layout(100, 53);  // K = 2, N = 100: device line table
    Morpher m(w, h, PixelFormat::Rgba8, {key(a.data(), base), key(b.data(), jitter(base, 0.05f, 54))},
              Backend::Cuda);
    std::vector<Layout> targets;
    for (int f = 0; f < 6; ++f) targets.push_back(jitter(base, 0.04f, 60 + f));
    const std::vector<float> weights{0.4f, 0.6f};

    std::vector<std::vector<std::uint8_t>> expected(targets.size(), std::vector<std::uint8_t>(a.size()));
    for (std::size_t f = 0; f < targets.size(); ++f) m.morph_to_host(targets[f], weights, {}, expected[f].data());

    std::vector<unsigned char*> device(targets.size());
    std::size_t pitch = 0;
    for (auto& d : device) {
        void* p = nullptr;
        CUDA_OK(cudaMallocPitch(&p, &pitch, w * 4 + 12, h));  // pitch wider than a row
        d = static_cast<unsigned char*>(p);
    }
    for (std::size_t f = 0; f < targets.size(); ++f) m.morph_to_device(targets[f], weights, {}, device[f], pitch);
    m.synchronize();
    std::vector<std::uint8_t> got(a.size());
    for (std::size_t f = 0; f < targets.size(); ++f) {
        CUDA_OK(cudaMemcpy2D(got.data(), w * 4, device[f], pitch, w * 4, h, cudaMemcpyDeviceToHost));
        EXPECT_EQ(max_abs_diff(got, expected[f]), 0.0) << "frame " << f;
        cudaFree(device[f]);
    }

    cudaArray_t array = nullptr;
    const cudaChannelFormatDesc desc = cudaCreateChannelDesc<uchar4>();
    CUDA_OK(cudaMallocArray(&array, &desc, w, h, cudaArraySurfaceLoadStore));
    cudaResourceDesc res{};
    res.resType = cudaResourceTypeArray;
    res.res.array.array = array;
    cudaSurfaceObject_t surface = 0;
    CUDA_OK(cudaCreateSurfaceObject(&surface, &res));
    for (Accuracy acc : {Accuracy::Exact, Accuracy::Fast}) {
        MorphParams params;
        params.accuracy = acc;
        m.morph_to_host(targets[0], weights, params, expected[0].data());
        m.morph_to_surface(targets[0], weights, params, surface);
        m.synchronize();
        CUDA_OK(cudaMemcpy2DFromArray(got.data(), w * 4, array, 0, 0, w * 4, h, cudaMemcpyDeviceToHost));
        EXPECT_EQ(max_abs_diff(got, expected[0]), 0.0) << to_string(acc);
    }
    cudaDestroySurfaceObject(surface);
    cudaFreeArray(array);
}

TEST(MorphCuda, BadDeviceOutputsAreInputErrors) {
    SKIP_WITHOUT_CUDA();
    const auto img = random_rgba8(16, 16, 71);
    const Layout l = random_layout(3, 72);
    Morpher m(16, 16, PixelFormat::Rgba8, {key(img.data(), l)}, Backend::Cuda);
    void* p = nullptr;
    ASSERT_EQ(cudaMalloc(&p, 16 * 16 * 4), cudaSuccess);
    try {
        m.morph_to_device(l, {1.0f}, {}, p, 60);
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("morph: morph_to_device(): pitch_bytes = 60, expected at least 64"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_THROW(m.morph_to_device(l, {1.0f}, {}, nullptr, 64), InputError);
    EXPECT_THROW(m.morph_to_surface(l, {1.0f}, {}, 0), InputError);
    cudaFree(p);
}

}  // namespace
}  // namespace emoface::morph
