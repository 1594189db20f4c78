#include "emoface/render/ambient_occlusion.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "emoface/common/error.h"
#include "emoface/common/parallel.h"

namespace emoface::render {
namespace {

// Directions per parallel chunk: each chunk keeps its own height map and
// sums, added up in chunk order afterwards (the same result on any threads).
constexpr int kDirectionsPerChunk = 4;
constexpr float kMinCos = 0.15f;

// Point i of n on the unit sphere, evenly spread (Fibonacci lattice).
glm::vec3 lattice_direction(int i, int n) {
    const float golden = 2.39996323f;  // pi (3 - sqrt 5)
    const float z = 1.0f - (2.0f * float(i) + 1.0f) / float(n);
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    const float phi = golden * float(i);
    return {r * std::cos(phi), r * std::sin(phi), z};
}

struct Frame {
    glm::vec3 u, w, d;
};
Frame frame_of(const glm::vec3& d) {
    const glm::vec3 a = std::abs(d.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
    const glm::vec3 u = glm::normalize(glm::cross(d, a));
    return {u, glm::cross(d, u), d};
}

// Point i of n on the cap of half-angle `cos_max` (its cosine) around the
// frame's axis, evenly spread by area (a Fibonacci spiral).
glm::vec3 cap_direction(int i, int n, float cos_max, const Frame& axis) {
    const float golden = 2.39996323f;
    const float z = 1.0f - (1.0f - cos_max) * (float(i) + 0.5f) / float(n);
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    const float phi = golden * float(i);
    return glm::normalize(r * std::cos(phi) * axis.u + r * std::sin(phi) * axis.w + z * axis.d);
}

}  // namespace

std::vector<float> bake_vertex_occlusion(const std::vector<glm::vec3>& positions,
                                         const std::vector<glm::vec3>& normals,
                                         const std::vector<unsigned>& triangles,
                                         const OcclusionSpec& spec) {
    const std::size_t n = positions.size();
    if (normals.size() != n)
        fail("render: bake_vertex_occlusion: {} normals for {} positions, expected one each", normals.size(), n);
    if (triangles.size() % 3 != 0)
        fail("render: bake_vertex_occlusion: {} triangle indices, expected a multiple of 3", triangles.size());
    for (unsigned i : triangles)
        if (i >= n) fail("render: bake_vertex_occlusion: triangle index {}, expected < {}", i, n);
    if (!(spec.texel_mm > 0.0f) || spec.directions < 1 || !(spec.far_mm > spec.near_mm))
        fail("render: bake_vertex_occlusion: expected texel_mm > 0, directions >= 1, far_mm > near_mm; "
             "found {}, {}, {} <= {}", spec.texel_mm, spec.directions, spec.far_mm, spec.near_mm);
    const bool cone = glm::length(spec.cone_axis) > 0.0f;
    if (cone && !(spec.cone_half_angle_deg >= 0.0f && spec.cone_half_angle_deg < 90.0f))
        fail("render: bake_vertex_occlusion: a light's cone of {} degrees, expected 0 to 90",
             spec.cone_half_angle_deg);
    const Frame cone_frame = frame_of(cone ? glm::normalize(spec.cone_axis) : glm::vec3(0, 0, 1));
    const float cone_cos = std::cos(glm::radians(spec.cone_half_angle_deg));
    const float up_weight = cone ? 0.0f : spec.up_weight;
    std::vector<float> open(n, 1.0f);
    if (n == 0 || triangles.empty()) return open;

    // The maps of every direction cover the mesh's bounding sphere.
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (const auto& p : positions) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    const glm::vec3 centre = 0.5f * (lo + hi);
    const float radius = 0.5f * glm::length(hi - lo) + spec.texel_mm;
    const int side = int(std::ceil(2.0f * radius / spec.texel_mm)) + 1;
    if (side > 8192)
        fail("render: bake_vertex_occlusion: a {}-texel map ({} wide at {} per texel), expected at most 8192",
             side, 2.0f * radius, spec.texel_mm);

    std::vector<glm::vec3> unit(n);
    for (std::size_t i = 0; i < n; ++i) {
        const float len = glm::length(normals[i]);
        unit[i] = len > 0.0f ? normals[i] / len : glm::vec3(0.0f);
    }

    const int k = spec.directions;
    const int chunks = (k + kDirectionsPerChunk - 1) / kDirectionsPerChunk;
    std::vector<std::vector<float>> blocked(static_cast<std::size_t>(chunks));
    std::vector<std::vector<float>> seen(static_cast<std::size_t>(chunks));
    const float inv_texel = 1.0f / spec.texel_mm;
    parallel_for(k, kDirectionsPerChunk, [&](int begin, int end) {
        std::vector<float> height(std::size_t(side) * side);
        std::vector<glm::vec3> q(n);  // x, y in texels, z (height) in mm
        // A call may hold several chunks (run inline, it holds them all).
        for (int dir = begin; dir < end; ++dir) {
            const std::size_t c = std::size_t(dir / kDirectionsPerChunk);
            std::vector<float>& sum_blocked = blocked[c];
            std::vector<float>& sum_seen = seen[c];
            if (sum_seen.empty()) {
                sum_blocked.assign(n, 0.0f);
                sum_seen.assign(n, 0.0f);
            }
            const Frame f = frame_of(cone ? cap_direction(dir, k, cone_cos, cone_frame) : lattice_direction(dir, k));
            const float ox = glm::dot(centre, f.u) - radius, oy = glm::dot(centre, f.w) - radius;
            for (std::size_t i = 0; i < n; ++i)
                q[i] = {(glm::dot(positions[i], f.u) - ox) * inv_texel,
                        (glm::dot(positions[i], f.w) - oy) * inv_texel, glm::dot(positions[i], f.d)};
            std::fill(height.begin(), height.end(), -std::numeric_limits<float>::infinity());
            // Rasterise: texel (x, y) has its centre at (x + 0.5, y + 0.5);
            // shared edges are covered by both triangles (the higher wins).
            for (std::size_t t = 0; t < triangles.size(); t += 3) {
                const glm::vec3 &a = q[triangles[t]], &b = q[triangles[t + 1]], &e = q[triangles[t + 2]];
                const float area = (b.x - a.x) * (e.y - a.y) - (b.y - a.y) * (e.x - a.x);
                if (std::abs(area) < 1e-12f) continue;
                const float inv_area = 1.0f / area;
                const int x0 = std::max(0, int(std::ceil(std::min({a.x, b.x, e.x}) - 0.5f)));
                const int x1 = std::min(side - 1, int(std::floor(std::max({a.x, b.x, e.x}) - 0.5f)));
                const int y0 = std::max(0, int(std::ceil(std::min({a.y, b.y, e.y}) - 0.5f)));
                const int y1 = std::min(side - 1, int(std::floor(std::max({a.y, b.y, e.y}) - 0.5f)));
                for (int y = y0; y <= y1; ++y) {
                    const float py = float(y) + 0.5f;
                    for (int x = x0; x <= x1; ++x) {
                        const float px = float(x) + 0.5f;
                        // Barycentric weights of b and e; a gets the rest.
                        const float wb = ((px - a.x) * (e.y - a.y) - (py - a.y) * (e.x - a.x)) * inv_area;
                        const float we = ((b.x - a.x) * (py - a.y) - (b.y - a.y) * (px - a.x)) * inv_area;
                        const float wa = 1.0f - wb - we;
                        const float eps = -1e-5f;
                        if (wa < eps || wb < eps || we < eps) continue;
                        float& h = height[std::size_t(y) * side + x];
                        h = std::max(h, wa * a.z + wb * b.z + we * e.z);
                    }
                }
            }
            for (std::size_t i = 0; i < n; ++i) {
                // Directions within 9 degrees of the tangent plane are left
                // out: the surface's own slope across a texel is not told
                // apart from an occluder there (2 % of a cosine-weighted
                // hemisphere).
                const float cos_theta = glm::dot(unit[i], f.d);
                if (cos_theta < kMinCos) continue;
                const float weight = cos_theta * (1.0f + up_weight * f.d.y);
                sum_seen[i] += weight;
                // Looked up from a little above the surface, so that its
                // own facets in the texel do not count.
                const glm::vec3 lifted = (positions[i] + spec.bias_mm * unit[i]);
                const float lx = (glm::dot(lifted, f.u) - ox) * inv_texel, ly = (glm::dot(lifted, f.w) - oy) * inv_texel;
                const int x = std::clamp(int(lx), 0, side - 1), y = std::clamp(int(ly), 0, side - 1);
                const float above = height[std::size_t(y) * side + x] - glm::dot(lifted, f.d);
                const float tan_theta = std::sqrt(1.0f - cos_theta * cos_theta) / cos_theta;
                if (above <= spec.texel_mm * tan_theta) continue;
                const float s = std::clamp((above - spec.near_mm) / (spec.far_mm - spec.near_mm), 0.0f, 1.0f);
                sum_blocked[i] += weight * (1.0f - s * s * (3.0f - 2.0f * s));
            }
        }
    });
    for (std::size_t i = 0; i < n; ++i) {
        float b = 0.0f, s = 0.0f;
        for (int c = 0; c < chunks; ++c) {
            b += blocked[std::size_t(c)][i];
            s += seen[std::size_t(c)][i];
        }
        if (s > 0.0f) open[i] = std::clamp(1.0f - b / s, 0.0f, 1.0f);
    }
    return open;
}

}  // namespace emoface::render
