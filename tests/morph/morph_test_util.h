#pragma once
// Inputs shared by the morph tests: deterministic random images and layouts.
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "emoface/morph/morph.h"
#include "support/parity.h"

namespace emoface::morph::test {

// A smooth but busy RGBA8 image (sums of sinusoids plus noise), so a wrong
// position shows up as a wrong value.
inline std::vector<std::uint8_t> random_rgba8(int w, int h, unsigned seed, double noise = 40.0) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> phase(0.0, 6.28), freq(2.0, 9.0), n(-noise, noise);
    double f[4][2], ph[4];
    for (int c = 0; c < 4; ++c) {
        f[c][0] = freq(rng);
        f[c][1] = freq(rng);
        ph[c] = phase(rng);
    }
    std::vector<std::uint8_t> img(static_cast<std::size_t>(w) * h * 4);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 4; ++c) {
                const double v = 127.5 + 90.0 * std::sin(f[c][0] * x / w * 6.28 + f[c][1] * y / h * 6.28 + ph[c]) +
                                 n(rng);
                img[(static_cast<std::size_t>(y) * w + x) * 4 + c] =
                    static_cast<std::uint8_t>(std::lround(std::fmin(255.0, std::fmax(0.0, v))));
            }
    return img;
}

inline std::vector<float> to_float(const std::vector<std::uint8_t>& img) {
    std::vector<float> out(img.size());
    for (std::size_t i = 0; i < img.size(); ++i) out[i] = img[i] / 255.0f;
    return out;
}

// Unit normals encoded 0.5 + 0.5 n, tilted up to ~60 degrees from +z.
inline std::vector<float> random_normals(int w, int h, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> t(-0.9, 0.9);
    std::vector<float> img(static_cast<std::size_t>(w) * h * 4);
    for (std::size_t i = 0; i < img.size() / 4; ++i) {
        double n[3] = {t(rng), t(rng), 1.0};
        const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int c = 0; c < 3; ++c) img[4 * i + c] = static_cast<float>(0.5 + 0.5 * n[c] / len);
        img[4 * i + 3] = 1.0f;
    }
    return img;
}

inline std::vector<std::uint8_t> quantise(const std::vector<float>& img) {
    std::vector<std::uint8_t> out(img.size());
    for (std::size_t i = 0; i < img.size(); ++i)
        out[i] = static_cast<std::uint8_t>(std::lround(std::fmin(1.0, std::fmax(0.0, img[i])) * 255.0));
    return out;
}

// N lines inside [0.1, 0.9]², lengths 0.05 to 0.3.
inline Layout random_layout(int n, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> pos(0.1f, 0.9f), len(0.05f, 0.3f), ang(0.0f, 6.2831853f);
    Layout l;
    for (int i = 0; i < n; ++i) {
        const float x = pos(rng), y = pos(rng), r = len(rng), a = ang(rng);
        l.push_back({x, y, x + r * std::cos(a), y + r * std::sin(a)});
    }
    return l;
}

// Each end point moved by up to `amount` (normalised units).
inline Layout jitter(const Layout& base, float amount, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> d(-amount, amount);
    Layout l = base;
    for (Line& line : l) {
        line.px += d(rng);
        line.py += d(rng);
        line.qx += d(rng);
        line.qy += d(rng);
    }
    return l;
}

// K random key maps of one size in both encodings (unit normals when
// normal_map), with layouts jittered from `base`; each KeyMap points at the
// pixels of `format`. The pixels live here, beside the KeyMaps that point at
// them.
struct RandomKeys {
    std::vector<std::vector<float>> floats;
    std::vector<std::vector<std::uint8_t>> bytes;
    std::vector<KeyMap> keys;
};

inline RandomKeys random_keys(int w, int h, int count, PixelFormat format, bool normal_map, const Layout& base,
                              unsigned seed) {
    RandomKeys r;
    for (int k = 0; k < count; ++k) {
        r.floats.push_back(normal_map ? random_normals(w, h, seed + k) : to_float(random_rgba8(w, h, seed + k)));
        r.bytes.push_back(quantise(r.floats.back()));
    }
    for (int k = 0; k < count; ++k) {
        KeyMap key;
        key.pixels = format == PixelFormat::Rgba8 ? static_cast<const void*>(r.bytes[k].data()) : r.floats[k].data();
        key.layout = jitter(base, 0.05f, seed + 10 + k);
        r.keys.push_back(key);
    }
    return r;
}

// Fails on NaN and on a size mismatch (tests/support/parity.h).
using emoface::testing::max_abs_diff;

}  // namespace emoface::morph::test
