// Plain-loop double-precision Beier-Neely, kept deliberately naive: u, v and
// X' straight from the thesis's formulas, the distance by cases.
#include "emoface/morph/reference.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace emoface::morph {
namespace {

struct V2 {
    double x, y;
};
V2 operator-(V2 a, V2 b) { return {a.x - b.x, a.y - b.y}; }
V2 operator+(V2 a, V2 b) { return {a.x + b.x, a.y + b.y}; }
V2 operator*(double s, V2 a) { return {s * a.x, s * a.y}; }
double dot(V2 a, V2 b) { return a.x * b.x + a.y * b.y; }
double norm(V2 a) { return std::sqrt(dot(a, a)); }
V2 perp(V2 a) { return {-a.y, a.x}; }

struct Frame {
    double sx, sy, extent;
};
Frame frame_of(int width, int height) {
    const double s = std::max(width, height);
    return {width / s, height / s, s};
}
V2 start(const Line& l, const Frame& f) { return {l.px * f.sx, l.py * f.sy}; }
V2 end(const Line& l, const Frame& f) { return {l.qx * f.sx, l.qy * f.sy}; }

// Source position (pixels) for output pixel centre X (iso units).
V2 source_position(V2 X, const Layout& target, const Layout& source, const MorphParams& params, const Frame& f) {
    V2 sum{0.0, 0.0};
    double weight_sum = 0.0;
    for (std::size_t i = 0; i < target.size(); ++i) {
        const V2 P = start(target[i], f), Q = end(target[i], f);
        const V2 Ps = start(source[i], f), Qs = end(source[i], f);
        const V2 d = Q - P, ds = Qs - Ps;
        const double u = dot(X - P, d) / dot(d, d);
        const double v = dot(X - P, perp(d)) / norm(d);
        const V2 Xs = Ps + u * ds + (v / norm(ds)) * perp(ds);
        double dist;
        if (u < 0.0)
            dist = norm(X - P);
        else if (u > 1.0)
            dist = norm(X - Q);
        else
            dist = std::abs(v);
        const double w = std::pow(std::pow(norm(d), params.p) / (params.a + dist), params.b);
        sum = sum + w * (Xs - X);
        weight_sum += w;
    }
    const V2 D = weight_sum > 0.0 ? (1.0 / weight_sum) * sum : V2{0.0, 0.0};
    return f.extent * (X + D);
}

struct Texel {
    double c[4];
};

// A key is its pixels on the texels its region touches (x from floor(x0 W)
// to ceil(x1 W), likewise y) and rest everywhere else.
bool in_region(const KeyMap& key, int width, int height, int x, int y) {
    const Region& r = key.region;
    return x >= std::floor(r.x0 * width) && x < std::ceil(r.x1 * width) && y >= std::floor(r.y0 * height) &&
           y < std::ceil(r.y1 * height);
}

Texel texel(const KeyMap& key, PixelFormat format, int width, int height, int x, int y, const Texel& rest) {
    if (!in_region(key, width, height, x, y)) return rest;
    Texel t{};
    const std::size_t i = static_cast<std::size_t>(y) * width + x;
    if (format == PixelFormat::Rgba8) {
        const auto* p = static_cast<const std::uint8_t*>(key.pixels) + 4 * i;
        for (int c = 0; c < 4; ++c) t.c[c] = p[c];
    } else {
        const auto* p = static_cast<const float*>(key.pixels) + 4 * i;
        for (int c = 0; c < 4; ++c) t.c[c] = p[c];
    }
    return t;
}

Texel bilinear(const KeyMap& key, PixelFormat format, int width, int height, V2 pos, const Texel& rest) {
    const double fx = std::clamp(std::isfinite(pos.x) ? pos.x - 0.5 : 0.0, 0.0, width - 1.0);
    const double fy = std::clamp(std::isfinite(pos.y) ? pos.y - 0.5 : 0.0, 0.0, height - 1.0);
    const int x0 = static_cast<int>(std::floor(fx)), y0 = static_cast<int>(std::floor(fy));
    const int x1 = std::min(x0 + 1, width - 1), y1 = std::min(y0 + 1, height - 1);
    const double tx = fx - x0, ty = fy - y0;
    const Texel a = texel(key, format, width, height, x0, y0, rest), b = texel(key, format, width, height, x1, y0, rest);
    const Texel c = texel(key, format, width, height, x0, y1, rest), d = texel(key, format, width, height, x1, y1, rest);
    Texel out{};
    for (int i = 0; i < 4; ++i)
        out.c[i] = (1 - ty) * ((1 - tx) * a.c[i] + tx * b.c[i]) + ty * ((1 - tx) * c.c[i] + tx * d.c[i]);
    return out;
}

}  // namespace

void reference_positions(int width, int height, const std::vector<Layout>& key_layouts, const Layout& target,
                         const MorphParams& params, std::vector<double>& out) {
    const Frame f = frame_of(width, height);
    const std::size_t K = key_layouts.size();
    out.assign(static_cast<std::size_t>(width) * height * K * 2, 0.0);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const V2 X{(x + 0.5) / f.extent, (y + 0.5) / f.extent};
            for (std::size_t k = 0; k < K; ++k) {
                const V2 s = source_position(X, target, key_layouts[k], params, f);
                const std::size_t i = ((static_cast<std::size_t>(y) * width + x) * K + k) * 2;
                out[i] = s.x;
                out[i + 1] = s.y;
            }
        }
}

void reference_morph(int width, int height, PixelFormat format, const std::vector<KeyMap>& keys,
                     const Layout& target, const std::vector<float>& weights, const MorphParams& params, void* out) {
    const Frame f = frame_of(width, height);
    const double unit = format == PixelFormat::Rgba8 ? 255.0 : 1.0;
    Texel rest{};
    for (int i = 0; i < 4; ++i) rest.c[i] = params.rest[i] * unit;
    double weight_sum = 0.0;
    for (float w : weights) weight_sum += w;
    // out = Σ w_k key_k + (1 − Σ w) rest, clamped to the format's range where
    // rest has a share (morph.h, MorphParams::rest).
    const double share = 1.0 - weight_sum;
    const bool convex = std::abs(share) <= 1e-5;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const V2 X{(x + 0.5) / f.extent, (y + 0.5) / f.extent};
            double c[4] = {0, 0, 0, 0};
            for (std::size_t k = 0; k < keys.size(); ++k) {
                if (weights[k] <= 0.0f) continue;
                const Texel t = bilinear(keys[k], format, width, height,
                                         source_position(X, target, keys[k].layout, params, f), rest);
                for (int i = 0; i < 4; ++i) c[i] += weights[k] * t.c[i];
            }
            if (!convex) {
                for (int i = 0; i < 4; ++i) c[i] += share * rest.c[i];
                if (params.normal_map || format == PixelFormat::Rgba8)
                    for (double& v : c) v = std::clamp(v, 0.0, unit);
            }
            if (params.normal_map) {
                double n[3];
                for (int i = 0; i < 3; ++i) n[i] = 2.0 * c[i] / unit - 1.0;
                const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
                if (len > 1e-6) {
                    for (double& v : n) v /= len;
                } else {
                    n[0] = 0;
                    n[1] = 0;
                    n[2] = 1;
                }
                for (int i = 0; i < 3; ++i) c[i] = (0.5 + 0.5 * n[i]) * unit;
            }
            const std::size_t i = static_cast<std::size_t>(y) * width + x;
            if (format == PixelFormat::Rgba8) {
                auto* p = static_cast<std::uint8_t*>(out) + 4 * i;
                for (int ch = 0; ch < 4; ++ch) p[ch] = static_cast<std::uint8_t>(std::lround(std::clamp(c[ch], 0.0, 255.0)));
            } else {
                auto* p = static_cast<float*>(out) + 4 * i;
                for (int ch = 0; ch < 4; ++ch) p[ch] = static_cast<float>(c[ch]);
            }
        }
}

}  // namespace emoface::morph
