#include "skin_maps.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "emoface/common/constants.h"
#include "emoface/common/error.h"

namespace emoface::render::detail {
namespace {


// The ring integrals of one Gaussian of the profile, for a point whose normal
// makes angle theta with the light on a circle of radius r (mm): numerator
// (light arriving along the ring, clamped cosine) and denominator (the ring's
// weight). The Gaussian is sampled over +-6 sigma of arc (or the whole ring).
void ring_integrals(double variance, double theta, double r, double* num, double* den) {
    const double sigma = std::sqrt(variance);
    const double half = std::min(kPi * r, 6.0 * sigma);
    constexpr int kSteps = 96;
    const double ds = 2.0 * half / kSteps;
    double n = 0.0, d = 0.0;
    for (int k = 0; k < kSteps; ++k) {
        const double s = -half + (k + 0.5) * ds;  // arc length from the point
        const double chord = 2.0 * r * std::sin(s / (2.0 * r));
        const double g = std::exp(-chord * chord / (2.0 * variance)) / (2.0 * kPi * variance);
        n += std::max(0.0, std::cos(theta + s / r)) * g;
        d += g;
    }
    *num = n * ds;
    *den = d * ds;
}

std::uint32_t hash3(std::uint32_t x, std::uint32_t y, std::uint32_t seed) {
    std::uint32_t h = x * 374761393u + y * 668265263u + seed * 2246822519u;
    h = (h ^ (h >> 13)) * 1274126177u;
    return h ^ (h >> 16);
}
double unit(std::uint32_t h) { return double(h & 0xffffffu) / double(0xffffffu); }

// Value noise of period `period` lattice cells (tileable).
double periodic_noise(double x, double y, int period, std::uint32_t seed) {
    const int xi = int(std::floor(x)), yi = int(std::floor(y));
    const double fx = x - xi, fy = y - yi;
    auto fade = [](double t) { return t * t * (3.0 - 2.0 * t); };
    auto at = [&](int i, int j) {
        const int a = ((i % period) + period) % period, b = ((j % period) + period) % period;
        return unit(hash3(std::uint32_t(a), std::uint32_t(b), seed));
    };
    const double u = fade(fx), v = fade(fy);
    const double top = at(xi, yi) + (at(xi + 1, yi) - at(xi, yi)) * u;
    const double bottom = at(xi, yi + 1) + (at(xi + 1, yi + 1) - at(xi, yi + 1)) * u;
    return top + (bottom - top) * v;
}

}  // namespace

std::vector<float> preintegrated_scatter_table(const SkinShading& skin, int width, int height) {
    if (width < 2 || height < 2 || !(skin.max_curvature > 0.0f))
        fail("render: scatter table {}x{} with curvature up to {}", width, height,
             skin.max_curvature);
    std::vector<float> out(std::size_t(width) * height * 3);
    for (int j = 0; j < height; ++j) {
        const double curvature = (j + 0.5) / height * skin.max_curvature;
        const double r = 1.0 / curvature;
        for (int i = 0; i < width; ++i) {
            const double n_dot_l = -1.0 + 2.0 * (i + 0.5) / width;
            const double theta = std::acos(std::clamp(n_dot_l, -1.0, 1.0));
            double num[3] = {0, 0, 0}, den[3] = {0, 0, 0};
            for (const ScatterGaussian& g : skin.profile) {
                if (!(g.variance_mm2 > 0.0f)) continue;
                double gn = 0, gd = 0;
                ring_integrals(g.variance_mm2, theta, r, &gn, &gd);
                for (int c = 0; c < 3; ++c) {
                    num[c] += g.weight[c] * gn;
                    den[c] += g.weight[c] * gd;
                }
            }
            float* px = &out[(std::size_t(j) * width + i) * 3];
            for (int c = 0; c < 3; ++c)
                px[c] = den[c] > 0.0 ? float(num[c] / den[c]) : float(std::max(0.0, n_dot_l));
        }
    }
    return out;
}

std::vector<std::uint8_t> pore_map(const PoreMapSpec& spec) {
    if (spec.size < 8 || spec.size > 2048 || spec.size % 4 != 0 || spec.cells < 1 ||
        spec.cells > spec.size / 2)
        fail("render: pore map of {} texels (a multiple of 4 in 8..2048) with {} cells (1..size/2)",
             spec.size, spec.cells);
    const int n = spec.size;
    const double cell = double(n) / spec.cells;
    std::vector<double> height(std::size_t(n) * n, 0.0), pit(std::size_t(n) * n, 0.0);
    // The skin's microrelief: furrows in three families of lines that cross
    // (two steep, the third shallower), about one to a pore cell apart,
    // cutting the surface into small plateaus. Each family is the level
    // lines of a x + b y (integer a, b: so it tiles), warped by smooth
    // noise so the lines meander, and deepening and fading along them.
    struct Family {
        double a, b, weight;
        std::uint32_t seed;
    };
    std::array<Family, 3> families{};
    {
        const double count = 0.8 * spec.cells;  // lines across the tile per family
        const double angles[3] = {0.35, 1.45, 2.5}, weights[3] = {1.0, 0.85, 0.5};
        for (int k = 0; k < 3; ++k)
            families[std::size_t(k)] = {std::round(count * std::cos(angles[k])), std::round(count * std::sin(angles[k])),
                                        weights[k], spec.seed + 101u + 17u * std::uint32_t(k)};
    }
    const double spacing = n / (0.8 * spec.cells);  // texels between a family's lines
    auto furrows = [&](double x, double y) {
        double sum = 0.0;
        for (const Family& fam : families) {
            const double length = std::hypot(fam.a, fam.b);
            const double warp = 0.45 * (periodic_noise(x * 5.0 / n, y * 5.0 / n, 5, fam.seed) - 0.5) +
                                0.25 * (periodic_noise(x * 13.0 / n, y * 13.0 / n, 13, fam.seed + 1u) - 0.5);
            const double phase = (fam.a * x + fam.b * y) / n + warp;
            const double across = std::abs(phase - std::round(phase)) * n / length;  // texels to the line
            const double width = 0.13 * spacing;
            const double depth = 0.3 + 0.7 * periodic_noise(x * 24.0 / n, y * 24.0 / n, 24, fam.seed + 2u);
            sum += fam.weight * depth * std::exp(-across * across / (width * width));
        }
        return std::min(sum, 1.5);
    };
    // Pit centres and radii, one per cell, jittered.
    std::vector<double> cx(std::size_t(spec.cells) * spec.cells), cy(cx.size()), radius(cx.size());
    for (int j = 0; j < spec.cells; ++j)
        for (int i = 0; i < spec.cells; ++i) {
            const std::size_t k = std::size_t(j) * spec.cells + i;
            const std::uint32_t h = hash3(std::uint32_t(i), std::uint32_t(j), spec.seed);
            cx[k] = (i + 0.15 + 0.7 * unit(h)) * cell;
            cy[k] = (j + 0.15 + 0.7 * unit(hash3(h, 17u, spec.seed))) * cell;
            radius[k] = spec.pit_radius * cell * (0.6 + 0.8 * unit(hash3(h, 29u, spec.seed)));
        }
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const int ci = int(x / cell), cj = int(y / cell);
            double depth = 0.0;
            for (int dj = -1; dj <= 1; ++dj)
                for (int di = -1; di <= 1; ++di) {
                    // Neighbouring cells across the tile's edge wrap around.
                    const int i = ((ci + di) % spec.cells + spec.cells) % spec.cells;
                    const int j = ((cj + dj) % spec.cells + spec.cells) % spec.cells;
                    const std::size_t k = std::size_t(j) * spec.cells + i;
                    double dx = x + 0.5 - cx[k], dy = y + 0.5 - cy[k];
                    dx -= n * std::round(dx / n);
                    dy -= n * std::round(dy / n);
                    const double q = (dx * dx + dy * dy) / (radius[k] * radius[k]);
                    if (q < 1.0) depth = std::max(depth, (1.0 - q) * (1.0 - q));
                }
            const std::size_t idx = std::size_t(y) * n + x;
            pit[idx] = depth;
            // Beside the furrows, a faint fine roughness: value noise on a
            // lattice of 2 texels, whose period divides the tile.
            const double f = periodic_noise(x / 2.0, y / 2.0, n / 2, spec.seed + 11u);
            height[idx] = spec.noise_scale * (0.5 * f - 2.0 * furrows(x + 0.5, y + 0.5)) - spec.pit_depth * depth;
        }
    // Normals from central differences (wrapping), scaled so the steepest
    // slope tilts the normal by 45 degrees; the shader scales the tilt.
    std::vector<double> gx(height.size()), gy(height.size());
    double steepest = 1e-12;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            auto h = [&](int xx, int yy) {
                return height[std::size_t((yy + n) % n) * n + std::size_t((xx + n) % n)];
            };
            const std::size_t idx = std::size_t(y) * n + x;
            gx[idx] = 0.5 * (h(x + 1, y) - h(x - 1, y));
            gy[idx] = 0.5 * (h(x, y + 1) - h(x, y - 1));
            steepest = std::max(steepest, std::hypot(gx[idx], gy[idx]));
        }
    std::vector<std::uint8_t> out(std::size_t(n) * n * 4);
    auto byte = [](double v) { return std::uint8_t(std::lround(std::clamp(v, 0.0, 1.0) * 255.0)); };
    for (std::size_t idx = 0; idx < height.size(); ++idx) {
        double nx = -gx[idx] / steepest, ny = -gy[idx] / steepest, nz = 1.0;
        const double len = std::sqrt(nx * nx + ny * ny + nz * nz);
        nx /= len; ny /= len; nz /= len;
        out[idx * 4 + 0] = byte(0.5 + 0.5 * nx);
        out[idx * 4 + 1] = byte(0.5 + 0.5 * ny);
        out[idx * 4 + 2] = byte(0.5 + 0.5 * nz);
        out[idx * 4 + 3] = byte(1.0 - 0.6 * pit[idx]);
    }
    return out;
}

std::vector<float> albedo_detail_slopes(const ImageRGBA8& image, float mean_levels,
                                        std::array<float, 2> hair_luminance) {
    const int w = image.width, h = image.height;
    if (w < 2 || h < 2 || image.pixels.size() != std::size_t(w) * h * 4 || !(mean_levels > 0.0f))
        fail("render: albedo detail of a {}x{} image with {} bytes (expected width*height*4, at least 2x2) "
             "over {} mip levels (expected > 0)",
             w, h, image.pixels.size(), mean_levels);
    if (!(hair_luminance[0] < hair_luminance[1]))
        fail("render: albedo detail: hair luminance range [{}, {}] (expected an increasing pair)", hair_luminance[0],
             hair_luminance[1]);
    double to_linear[256];
    for (int i = 0; i < 256; ++i) {
        const double c = i / 255.0;
        to_linear[i] = c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
    }
    // Linear luminance, rows bottom first.
    const std::size_t count = std::size_t(w) * h;
    std::vector<double> luma(count), mean(count), tmp(count);
    for (int r = 0; r < h; ++r)
        for (int x = 0; x < w; ++x) {
            const std::uint8_t* p = image.at(x, h - 1 - r);
            luma[std::size_t(r) * w + x] =
                0.2126 * to_linear[p[0]] + 0.7152 * to_linear[p[1]] + 0.0722 * to_linear[p[2]];
        }
    // The local mean: two passes of a box of 2 radius + 1 texels (clamped at
    // the edges), wide enough that the hair's clumps, not only its single
    // strands, stand out: the strands average away in the mips when the head
    // is seen whole, the clumps still break up its sheen.
    const int radius = std::max(1, int(std::lround(0.375 * std::exp2(double(mean_levels) + 2.0))));
    auto box = [&](const std::vector<double>& in, std::vector<double>& out, bool along_rows) {
        const int n = along_rows ? w : h, lines = along_rows ? h : w;
        for (int l = 0; l < lines; ++l) {
            auto at = [&](int k) {
                k = std::clamp(k, 0, n - 1);
                return along_rows ? std::size_t(l) * w + k : std::size_t(k) * w + l;
            };
            double sum = 0.0;
            for (int k = -radius; k <= radius; ++k) sum += in[at(k)];
            for (int k = 0; k < n; ++k) {
                out[at(k)] = sum / (2 * radius + 1);
                sum += in[at(k + radius + 1)] - in[at(k - radius)];
            }
        }
    };
    box(luma, tmp, true);
    box(tmp, mean, false);
    box(mean, tmp, true);
    box(tmp, mean, false);
    std::vector<double> height(count);
    for (std::size_t i = 0; i < count; ++i)
        height[i] = std::clamp(std::log(luma[i] + 0.004) - std::log(mean[i] + 0.004), -0.5, 0.5);
    // Hair: where the local mean is dark (the scalp's hair, the brows' body;
    // a mole, a nostril or a single hair is too small to darken the mean).
    std::vector<double> hair(count);
    for (std::size_t i = 0; i < count; ++i) {
        const double t = std::clamp((mean[i] - hair_luminance[0]) / double(hair_luminance[1] - hair_luminance[0]), 0.0, 1.0);
        hair[i] = 1.0 - t * t * (3.0 - 2.0 * t);
    }
    std::vector<float> out(count * 3);
    for (int r = 0; r < h; ++r)
        for (int x = 0; x < w; ++x) {
            auto at = [&](int xx, int rr) {
                return height[std::size_t(std::clamp(rr, 0, h - 1)) * w + std::size_t(std::clamp(xx, 0, w - 1))];
            };
            const std::size_t i = std::size_t(r) * w + x;
            // Where hair meets skin the height steps from hair below its
            // mean to skin above it: a ridge on the skin's side whose slope
            // drew a dark line along the hairline. Fade it across the edge.
            const double fade = 1.0 - 4.0 * hair[i] * (1.0 - hair[i]);
            out[3 * i + 0] = float(fade * 0.5 * (at(x + 1, r) - at(x - 1, r)) * w);
            out[3 * i + 1] = float(fade * 0.5 * (at(x, r + 1) - at(x, r - 1)) * h);
            out[3 * i + 2] = float(hair[i]);
        }
    return out;
}

std::vector<float> vertex_values_in_uv(const std::vector<glm::vec2>& uvs, const std::vector<unsigned>& triangles,
                                       const std::vector<float>& values, int width, int height, int dilate,
                                       float empty) {
    if (values.size() != uvs.size())
        fail("render: vertex_values_in_uv: {} values for {} vertices, expected one each", values.size(), uvs.size());
    if (triangles.size() % 3 != 0)
        fail("render: vertex_values_in_uv: {} triangle indices, expected a multiple of 3", triangles.size());
    if (width < 1 || height < 1 || dilate < 0)
        fail("render: vertex_values_in_uv: a {}x{} map grown {} texels, expected a positive size", width, height,
             dilate);
    for (unsigned i : triangles)
        if (i >= uvs.size()) fail("render: vertex_values_in_uv: triangle index {}, expected < {}", i, uvs.size());
    const std::size_t texels = std::size_t(width) * std::size_t(height);
    std::vector<float> out(texels, 0.0f);
    std::vector<char> painted(texels, 0);
    for (std::size_t t = 0; t < triangles.size(); t += 3) {
        glm::vec2 q[3];
        float v[3];
        for (int k = 0; k < 3; ++k) {
            const unsigned i = triangles[t + std::size_t(k)];
            q[k] = {uvs[i].x * float(width), uvs[i].y * float(height)};
            v[k] = values[i];
        }
        const float area = (q[1].x - q[0].x) * (q[2].y - q[0].y) - (q[1].y - q[0].y) * (q[2].x - q[0].x);
        if (std::abs(area) < 1e-12f) continue;
        const float inv_area = 1.0f / area;
        const int x0 = std::max(0, int(std::ceil(std::min({q[0].x, q[1].x, q[2].x}) - 0.5f)));
        const int x1 = std::min(width - 1, int(std::floor(std::max({q[0].x, q[1].x, q[2].x}) - 0.5f)));
        const int y0 = std::max(0, int(std::ceil(std::min({q[0].y, q[1].y, q[2].y}) - 0.5f)));
        const int y1 = std::min(height - 1, int(std::floor(std::max({q[0].y, q[1].y, q[2].y}) - 0.5f)));
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) {
                const float px = float(x) + 0.5f, py = float(y) + 0.5f;
                const float w1 = ((px - q[0].x) * (q[2].y - q[0].y) - (py - q[0].y) * (q[2].x - q[0].x)) * inv_area;
                const float w2 = ((q[1].x - q[0].x) * (py - q[0].y) - (q[1].y - q[0].y) * (px - q[0].x)) * inv_area;
                const float w0 = 1.0f - w1 - w2;
                if (w0 < -1e-5f || w1 < -1e-5f || w2 < -1e-5f) continue;
                const std::size_t at = std::size_t(y) * std::size_t(width) + std::size_t(x);
                out[at] = w0 * v[0] + w1 * v[1] + w2 * v[2];
                painted[at] = 1;
            }
    }
    // Each step fills the empty texels beside painted ones, from the
    // painted neighbours alone (so a step grows one texel, in every
    // direction alike); only the empty texels are visited.
    std::vector<std::size_t> gutter;
    for (std::size_t i = 0; i < texels; ++i)
        if (!painted[i]) gutter.push_back(i);
    std::vector<std::pair<std::size_t, float>> filled;
    for (int step = 0; step < dilate && !gutter.empty(); ++step) {
        filled.clear();
        std::size_t kept = 0;
        for (const std::size_t at : gutter) {
            const int x = int(at % std::size_t(width)), y = int(at / std::size_t(width));
            float sum = 0.0f;
            int count = 0;
            for (int ny = std::max(y - 1, 0); ny <= std::min(y + 1, height - 1); ++ny)
                for (int nx = std::max(x - 1, 0); nx <= std::min(x + 1, width - 1); ++nx) {
                    const std::size_t n = std::size_t(ny) * std::size_t(width) + std::size_t(nx);
                    if (painted[n]) {
                        sum += out[n];
                        ++count;
                    }
                }
            if (count > 0)
                filled.emplace_back(at, sum / float(count));
            else
                gutter[kept++] = at;
        }
        gutter.resize(kept);
        for (const auto& [at, value] : filled) {
            out[at] = value;
            painted[at] = 1;
        }
    }
    for (std::size_t i = 0; i < texels; ++i)
        if (!painted[i]) out[i] = empty;
    return out;
}

}  // namespace emoface::render::detail
