#pragma once
// Benchmark inputs: key maps and face-like layouts, generated quickly and
// deterministically. Shared by bench/morph and bench/morph_opencv.
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "emoface/morph/morph.h"

namespace emoface::bench {

// A busy RGBA8 image: separable waves plus hashed noise (cheap at 4096²).
inline std::vector<std::uint8_t> make_image(int w, int h, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> f(3.0f, 40.0f), ph(0.0f, 6.28f);
    std::vector<float> col(static_cast<std::size_t>(w) * 4), row(static_cast<std::size_t>(h) * 4);
    for (int c = 0; c < 4; ++c) {
        const float fx = f(rng), fy = f(rng), px = ph(rng), py = ph(rng);
        for (int x = 0; x < w; ++x) col[4 * x + c] = 60.0f * std::sin(fx * x / w + px);
        for (int y = 0; y < h; ++y) row[4 * y + c] = 50.0f * std::sin(fy * y / h + py);
    }
    std::vector<std::uint8_t> img(static_cast<std::size_t>(w) * h * 4);
    std::uint32_t state = seed * 2654435761u + 1u;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 4; ++c) {
                state ^= state << 13;
                state ^= state >> 17;
                state ^= state << 5;
                const float v = 127.5f + col[4 * x + c] + row[4 * y + c] + static_cast<float>(state % 32) - 16.0f;
                img[(static_cast<std::size_t>(y) * w + x) * 4 + c] =
                    static_cast<std::uint8_t>(v < 0.0f ? 0.0f : (v > 255.0f ? 255.0f : v));
            }
    return img;
}

// N feature lines over a face-sized region (centres in [0.15, 0.85]²,
// lengths 0.03 to 0.10 of the side), as the 84 MPEG-4 feature points give.
inline morph::Layout make_base_layout(int n, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> pos(0.15f, 0.85f), len(0.03f, 0.10f), ang(0.0f, 6.2831853f);
    morph::Layout l;
    for (int i = 0; i < n; ++i) {
        const float cx = pos(rng), cy = pos(rng), r = 0.5f * len(rng), a = ang(rng);
        l.push_back({cx - r * std::cos(a), cy - r * std::sin(a), cx + r * std::cos(a), cy + r * std::sin(a)});
    }
    return l;
}

// A key expression's layout: the base moved by a smooth field (features move
// together, up to ~2% of the side, like brows and mouth corners) plus a
// small independent jitter of each end point.
inline morph::Layout make_key_layout(const morph::Layout& base, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> f(2.0f, 7.0f), ph(0.0f, 6.28f), j(-0.002f, 0.002f);
    const float fx1 = f(rng), fy1 = f(rng), p1 = ph(rng), fx2 = f(rng), fy2 = f(rng), p2 = ph(rng);
    auto move = [&](float& x, float& y) {
        x += 0.012f * std::sin(fx1 * x + fy1 * y + p1) + j(rng);
        y += 0.012f * std::sin(fx2 * x + fy2 * y + p2) + j(rng);
    };
    morph::Layout l = base;
    for (morph::Line& line : l) {
        move(line.px, line.py);
        move(line.qx, line.qy);
    }
    return l;
}

// The target between the keys: their weighted mean (as an emotion mixture's
// feature points are).
inline morph::Layout mix_layouts(const std::vector<morph::Layout>& keys, const std::vector<float>& w) {
    morph::Layout out(keys[0].size(), morph::Line{0, 0, 0, 0});
    for (std::size_t k = 0; k < keys.size(); ++k)
        for (std::size_t i = 0; i < out.size(); ++i) {
            out[i].px += w[k] * keys[k][i].px;
            out[i].py += w[k] * keys[k][i].py;
            out[i].qx += w[k] * keys[k][i].qx;
            out[i].qy += w[k] * keys[k][i].qy;
        }
    return out;
}

// Positive weights summing to 1.
inline std::vector<float> make_weights(int k, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.2f, 1.0f);
    std::vector<float> w(k);
    float sum = 0.0f;
    for (float& x : w) sum += (x = u(rng));
    for (float& x : w) x /= sum * 1.00001f;
    return w;
}

// One input set: K key maps with their layouts, and a few targets with
// weights. Key k shows images[image_of[k]] (images[k] where image_of is
// empty) within regions[k] (the whole map where regions is empty).
struct InputSet {
    std::vector<std::vector<std::uint8_t>> images;
    std::vector<int> image_of;
    std::vector<morph::Region> regions;
    std::vector<morph::Layout> layouts;
    std::vector<morph::Layout> targets;
    std::vector<std::vector<float>> weights;

    std::vector<morph::KeyMap> keys() const {
        std::vector<morph::KeyMap> k;
        for (std::size_t i = 0; i < layouts.size(); ++i) {
            morph::KeyMap m;
            m.pixels = images[image_of.empty() ? i : image_of[i]].data();
            m.layout = layouts[i];
            if (!regions.empty()) m.region = regions[i];
            k.push_back(m);
        }
        return k;
    }
};

inline InputSet make_input_set(int size, int lines, int keys, unsigned seed, int targets = 4) {
    InputSet s;
    const morph::Layout base = make_base_layout(lines, 1000 + lines);  // one face per N
    for (int k = 0; k < keys; ++k) {
        s.images.push_back(make_image(size, size, seed * 31 + k));
        s.layouts.push_back(make_key_layout(base, 77 + k));  // one layout per key expression
    }
    for (int t = 0; t < targets; ++t) {
        s.weights.push_back(make_weights(keys, seed * 131 + t));
        s.targets.push_back(mix_layouts(s.layouts, s.weights.back()));
    }
    return s;
}

// Per-Action-Unit wrinkle keys: a full neutral key and `au_keys` keys whose
// wrinkles cover a small region each (0.26² of the map, about 7%, spread
// over the face), each at its own layout; per target the neutral key and 4
// of the AU keys at weight 1 (a frame's active AUs), over flat skin. With
// `regions` false the same keys declare the whole map (what regions save).
// Two images serve all keys: the cost under test is the warp and the
// samples, not the upload.
inline InputSet make_au_input_set(int size, int lines, int au_keys, bool regions, unsigned seed, int targets = 4) {
    InputSet s;
    const morph::Layout base = make_base_layout(lines, 1000 + lines);
    s.images.push_back(make_image(size, size, seed * 31));
    s.images.push_back(make_image(size, size, seed * 31 + 1));
    for (int k = 0; k <= au_keys; ++k) {
        s.image_of.push_back(k == 0 ? 0 : 1);
        s.layouts.push_back(make_key_layout(base, 77 + k));
        const float x0 = 0.12f + 0.5f * static_cast<float>((k * 7) % 11) / 10.0f;
        const float y0 = 0.12f + 0.5f * static_cast<float>((k * 5) % 9) / 8.0f;
        s.regions.push_back(k == 0 || !regions ? morph::Region{} : morph::Region{x0, y0, x0 + 0.26f, y0 + 0.26f});
    }
    for (int t = 0; t < targets; ++t) {
        std::vector<float> w(au_keys + 1, 0.0f), mix(au_keys + 1, 0.0f);
        w[0] = 1.0f;
        for (int a = 0; a < 4; ++a) w[1 + (t * 5 + a * 3) % au_keys] = 1.0f;
        // The target layout: neutral moved a fifth of the way to each active key.
        mix[0] = 1.0f;
        for (int k = 1; k <= au_keys; ++k)
            if (w[k] > 0.0f) {
                mix[k] = 0.2f;
                mix[0] -= 0.2f;
            }
        s.weights.push_back(w);
        s.targets.push_back(mix_layouts(s.layouts, mix));
    }
    return s;
}

}  // namespace emoface::bench
