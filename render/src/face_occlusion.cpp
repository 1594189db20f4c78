#include "emoface/render/face_occlusion.h"

#include <algorithm>
#include <cmath>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "emoface/fap/feature_points.h"
#include "emoface/render/ambient_occlusion.h"
#include "mesh_triangles.h"

namespace emoface::render {
namespace {

bool is_interior(expression::VertexPart p) {
    return p == expression::VertexPart::MouthUpper || p == expression::VertexPart::MouthLower ||
           p == expression::VertexPart::Tongue;
}

// Lashes are strands: skin pieces of a few vertices that no triangle joins to
// the skin's surface (the rig carries them by welding). Rasterised at the
// bake's texel (1.6 mm) a row of 0.2 mm strands turns into a solid visor over
// the upper lid, whose shade the lid's skin then carries wherever it moves:
// a dark band like eyeshadow over eyes opened wide. They occlude nothing.
std::vector<char> strand_triangles(const std::vector<unsigned>& triangles, std::size_t n,
                                   const std::vector<expression::VertexPart>& parts) {
    constexpr std::size_t kStrandVertices = 16;
    std::vector<unsigned> root(n);
    for (std::size_t v = 0; v < n; ++v) root[v] = unsigned(v);
    auto find = [&](unsigned v) {
        while (root[v] != v) v = root[v] = root[root[v]];
        return v;
    };
    for (std::size_t t = 0; t < triangles.size(); t += 3)
        for (int k = 1; k < 3; ++k) root[find(triangles[t + std::size_t(k)])] = find(triangles[t]);
    std::vector<std::size_t> size(n, 0);
    for (std::size_t v = 0; v < n; ++v) ++size[find(unsigned(v))];
    std::vector<char> strand(triangles.size() / 3, 0);
    for (std::size_t t = 0; t < triangles.size(); t += 3) {
        const unsigned v = triangles[t];
        strand[t / 3] = char(size[find(v)] <= kStrandVertices &&
                             (parts.size() != n || parts[v] == expression::VertexPart::Skin));
    }
    return strand;
}

// Piecewise linear height (y) at `x` along a polyline ordered inner corner
// to outer, held flat past its ends.
float height_along(float x, const std::vector<glm::vec3>& line) {
    const float sign = line.back().x > line.front().x ? 1.0f : -1.0f;
    if (sign * (x - line.front().x) <= 0.0f) return line.front().y;
    for (std::size_t i = 1; i < line.size(); ++i)
        if (sign * (x - line[i].x) <= 0.0f) {
            const glm::vec3 q0 = line[i - 1], q1 = line[i];
            return glm::mix(q0.y, q1.y, (x - q0.x) / (q1.x - q0.x));
        }
    return line.back().y;
}

// How far the skin at `p` lies in the eye's surround that the lids and brow
// move (0..1): the upper lid from its margin up over the brow's underside,
// and the lower lid from its margin down over the lid's furrow, the inner
// canthus beside them; fading out past the eye's corners and behind the
// eyeball's centre. `upper` and `lower` are the margins' rest polylines
// (inner corner first), `brow` the brow's inner, top and outer points.
// `lower_part` gets how much of the weight is the lower lid's.
float orbit_weight(const glm::vec3& p, const std::vector<glm::vec3>& upper, const std::vector<glm::vec3>& lower,
                   const std::vector<glm::vec3>& brow, const glm::vec3& centre, float& lower_part) {
    lower_part = 0.0f;
    const glm::vec3 inner = upper.front(), outer = upper.back();
    const float a = (p.x - inner.x) / (outer.x - inner.x);  // 0 inner corner, 1 outer
    // Nasally the surround reaches under the brow's head, which AU1 and
    // AU4 move most: a weight ending at the corner left the rest shade of
    // that corner on the raised brow's underside.
    const float across = glm::smoothstep(-0.45f, -0.1f, a) * (1.0f - glm::smoothstep(1.0f, 1.25f, a));
    if (across <= 0.0f) return 0.0f;
    const float lid = height_along(p.x, upper), top = height_along(p.x, brow);
    const float up = glm::smoothstep(-1.5f, 0.5f, p.y - lid) * (1.0f - glm::smoothstep(top - 1.0f, top + 4.0f, p.y));
    const float below = height_along(p.x, lower) - p.y;
    const float down = glm::smoothstep(-0.5f, 0.5f, below) * (1.0f - glm::smoothstep(6.0f, 10.0f, below));
    const float front = glm::smoothstep(centre.z - 2.0f, centre.z + 2.0f, p.z);
    lower_part = down / std::max(up + down, 1e-6f);
    return across * std::min(up + down, 1.0f) * front;
}

// The bake of bake_face_occlusion (`spec` its directions; `interior_bake`:
// the mouth interior's own bake, else it is left open).
std::vector<float> bake_face(const expression::TriMesh& mesh, const expression::Face& face, const OcclusionSpec& spec,
                             bool interior_bake) {
    const std::size_t n = mesh.n_vertices();
    std::vector<glm::vec3> positions(n), normals(n);
    for (const auto vh : mesh.vertices()) {
        const auto& p = mesh.point(vh);
        const auto& nv = mesh.normal(vh);
        positions[std::size_t(vh.idx())] = {p[0], p[1], p[2]};
        normals[std::size_t(vh.idx())] = {nv[0], nv[1], nv[2]};
    }
    const std::vector<int> indices = triangle_indices(mesh);
    std::vector<unsigned> triangles(indices.begin(), indices.end());
    {
        const std::vector<char> strand = strand_triangles(triangles, n, face.parts);
        std::vector<unsigned> solid;
        solid.reserve(triangles.size());
        for (std::size_t t = 0; t < triangles.size(); t += 3)
            if (!strand[t / 3]) solid.insert(solid.end(), triangles.begin() + std::ptrdiff_t(t), triangles.begin() + std::ptrdiff_t(t + 3));
        triangles.swap(solid);
    }
    std::vector<float> open = bake_vertex_occlusion(positions, normals, triangles, spec);

    const bool parts_known = face.parts.size() == n;
    auto interior = [&](unsigned v) {
        return parts_known && is_interior(face.parts[v]);
    };
    // Bakes the vertices `keep` says, with the triangles among them that
    // `occludes` says, and returns the result per vertex of the whole mesh.
    auto bake_subset = [&](const std::vector<char>& keep, auto occludes, const OcclusionSpec& spec) {
        std::vector<int> local(n, -1);
        std::vector<glm::vec3> sp, sn;
        for (std::size_t v = 0; v < n; ++v)
            if (keep[v]) {
                local[v] = int(sp.size());
                sp.push_back(positions[v]);
                sn.push_back(normals[v]);
            }
        std::vector<unsigned> st;
        for (std::size_t t = 0; t < triangles.size(); t += 3) {
            const unsigned a = triangles[t], b = triangles[t + 1], c = triangles[t + 2];
            if (local[a] < 0 || local[b] < 0 || local[c] < 0 || !occludes(a, b, c)) continue;
            st.insert(st.end(), {unsigned(local[a]), unsigned(local[b]), unsigned(local[c])});
        }
        const std::vector<float> sub = bake_vertex_occlusion(sp, sn, st, spec);
        std::vector<float> out(n, 1.0f);
        for (std::size_t v = 0; v < n; ++v)
            if (local[v] >= 0) out[v] = sub[std::size_t(local[v])];
        return out;
    };

    // Where the feature point lies on `mesh`: its vertex, so that a posed
    // mesh is baked with its posed lips and brows.
    auto point = [&](const char* id, glm::vec3& p) {
        const auto& fp = face.feature_points[std::size_t(fap::feature_point_index(id))];
        if (!fp.present) return false;
        p = fp.vertex >= 0 && std::size_t(fp.vertex) < n
                ? positions[std::size_t(fp.vertex)]
                : glm::vec3(float(fp.position[0]), float(fp.position[1]), float(fp.position[2]));
        return true;
    };

    // The lids keep a share of their rest shade. Their skin is the face's
    // most mobile (AU1, 2 and 5 lift the upper lid and the brow by up to
    // 10 mm and stretch it flat; AU4 and 43 fold it down; AU6 and 7 bunch
    // the lower lid), while the bake sees it only at rest, tucked under the
    // brow and in the socket: carried onto the raised, opened lid it drew a
    // dark band like eyeshadow over the eyes of fear, surprise and sadness,
    // and round the lower lid's furrow and the inner corner, with the key's
    // contact shadow (skin.json occlusion) that it drives, a dark smudgy
    // ring round every eye (blind review, session 9: the bake's share of
    // it, toggled off, is a ring from the brow's underside round the
    // furrow under the lower lid). A gentle shade stays (the lid's crease
    // and the brow still shade it a little in every pose); the lid's
    // shadow on the eyeball is the eye tile's (eye_texture.h).
    constexpr float kUpperShadeKept = 0.2f, kLowerShadeKept = 0.4f;
    const char* const brow_ids[2][3] = {{"4.1", "4.3", "4.5"}, {"4.2", "4.4", "4.6"}};
    if (parts_known)
        for (std::size_t side = 0; side < std::min<std::size_t>(face.eyeballs.size(), 2); ++side) {
            const auto& eb = face.eyeballs[side];
            std::vector<glm::vec3> brow(3);
            if (eb.upper_margin.size() < 2 || eb.lower_margin.size() < 2 || !point(brow_ids[side][0], brow[0]) ||
                !point(brow_ids[side][1], brow[1]) || !point(brow_ids[side][2], brow[2]))
                continue;
            auto polyline = [&](const std::vector<int>& vertices) {
                std::vector<glm::vec3> line;
                for (const int v : vertices) line.push_back(positions[std::size_t(v)]);
                // Inner corner first.
                if (std::abs(line.front().x) > std::abs(line.back().x)) std::reverse(line.begin(), line.end());
                return line;
            };
            const std::vector<glm::vec3> upper = polyline(eb.upper_margin), lower = polyline(eb.lower_margin);
            const glm::vec3 centre(float(eb.centre[0]), float(eb.centre[1]), float(eb.centre[2]));
            for (std::size_t v = 0; v < n; ++v) {
                if (face.parts[v] != expression::VertexPart::Skin || (positions[v].x > 0.0f) != (centre.x > 0.0f))
                    continue;
                float lower_part = 0.0f;
                const float w = orbit_weight(positions[v], upper, lower, brow, centre, lower_part);
                const float kept = glm::mix(kUpperShadeKept, kLowerShadeKept, lower_part);
                if (w > 0.0f) open[v] = glm::mix(open[v], 1.0f - kept * (1.0f - open[v]), w);
            }
        }
    glm::vec3 top, bottom, left, right, upper_border, lower_border;
    if (!parts_known || !point("2.2", top) || !point("2.3", bottom) || !point("2.4", left) || !point("2.5", right) ||
        !point("8.1", upper_border) || !point("8.2", lower_border))
        return open;
    const glm::vec3 mid = 0.5f * (top + bottom);
    const float half_width = 0.5f * std::abs(left.x - right.x);
    const float z_corner = 0.5f * (left.z + right.z);
    if (!(half_width > 0.0f)) return open;
    // The lips' weight: 1 over the vermilion and the slit, fading to 0 a few
    // mm past the borders and corners and behind the corners' depth.
    const float reach_up = std::max(upper_border.y - mid.y, 1.0f) + 3.0f;
    const float reach_down = std::max(mid.y - lower_border.y, 1.0f) + 3.0f;
    auto lip_weight = [&](const glm::vec3& p) {
        const float dx = (p.x - mid.x) / (half_width + 2.0f);
        const float dy = (p.y - mid.y) / (p.y >= mid.y ? reach_up : reach_down);
        const float e = dx * dx + dy * dy;
        const float front = glm::smoothstep(z_corner - 8.0f, z_corner - 2.0f, p.z);
        return (1.0f - glm::smoothstep(0.55f, 1.0f, e)) * front;
    };
    // The second lip bake: the skin within a head's lower half around the
    // mouth, the lips' own triangles out (but for the outermost, so that the
    // skin beyond the border still shades itself).
    constexpr float kNear = 90.0f;  // mm around the mouth: nose, cheeks and chin
    std::vector<char> near(n, 0);
    std::vector<float> lip(n, 0.0f);
    bool any = false;
    for (std::size_t v = 0; v < n; ++v) {
        if (interior(unsigned(v)) || glm::length(positions[v] - mid) > kNear) continue;
        near[v] = 1;
        lip[v] = lip_weight(positions[v]);
        any = any || lip[v] > 0.0f;
    }
    if (any) {
        const std::vector<float> lips_open =
            bake_subset(near, [&](unsigned a, unsigned b, unsigned c) { return lip[a] + lip[b] + lip[c] < 0.3f; },
                        spec);
        for (std::size_t v = 0; v < n; ++v)
            if (lip[v] > 0.0f) open[v] = glm::mix(open[v], std::max(open[v], lips_open[v]), lip[v]);
    }

    if (!interior_bake) return open;
    std::vector<char> inside(n, 0);
    bool any_inside = false;
    for (std::size_t v = 0; v < n; ++v) any_inside = (inside[v] = char(interior(unsigned(v)))) || any_inside;
    if (any_inside) {
        // Finer than the skin's bake: a tooth is 5-10 mm wide, and the
        // shade between neighbours is what tells them apart.
        OcclusionSpec fine;
        fine.texel_mm = 0.4f;
        fine.bias_mm = 0.25f;
        const std::vector<float> cavity =
            bake_subset(inside, [](unsigned, unsigned, unsigned) { return true; }, fine);
        // The lips and cheeks cover the interior more the deeper it lies
        // behind where the lips meet: the incisors' faces (about 6 mm
        // behind) keep nearly all the light, the molars (about 35 mm) 40 %,
        // the back of the cavity a third (light the tongue and teeth pass
        // on). The interior's own bake counts less (square root, over a
        // floor): its cavity is closed but for the lips' opening, a harsher
        // occluder than the open mouth it stands for, and the mucosa
        // scatters light on: nothing in it is black.
        constexpr float kCoverMm = 18.0f, kDeepest = 0.3f, kFloor = 0.35f;
        for (std::size_t v = 0; v < n; ++v)
            if (inside[v]) {
                const float depth = std::max(mid.z - positions[v].z - 4.0f, 0.0f);
                const float own = kFloor + (1.0f - kFloor) * std::sqrt(cavity[v]);
                open[v] = own * (kDeepest + (1.0f - kDeepest) * std::exp(-depth / kCoverMm));
            }
    }
    return open;
}

}  // namespace

std::vector<float> bake_face_occlusion(const expression::TriMesh& mesh, const expression::Face& face) {
    return bake_face(mesh, face, OcclusionSpec{}, true);
}

std::vector<float> bake_face_light_visibility(const expression::TriMesh& mesh, const expression::Face& face,
                                              const glm::vec3& toward_light, float half_angle_deg, int samples) {
    OcclusionSpec spec;
    spec.cone_axis = toward_light;
    spec.cone_half_angle_deg = half_angle_deg;
    spec.directions = samples;
    std::vector<float> visible = bake_face(mesh, face, spec, false);
    // The height maps' 1.6 mm texels and the vertices' rows stair-step a
    // shadow's edge: along the neck, under the jaw's shadow, the steps drew
    // light streaks down the skin at 512 px. A few rounds of averaging with
    // the 1-ring (about 2 mm each on the default face) round them off.
    constexpr int kSmoothingRounds = 8;
    const std::size_t n = visible.size();
    const std::vector<int> triangles = triangle_indices(mesh);
    std::vector<float> sum(n), count(n);
    for (int round = 0; round < kSmoothingRounds; ++round) {
        std::fill(sum.begin(), sum.end(), 0.0f);
        std::fill(count.begin(), count.end(), 0.0f);
        for (std::size_t t = 0; t < triangles.size(); t += 3)
            for (std::size_t a = t; a < t + 3; ++a)
                for (std::size_t b = t; b < t + 3; ++b) {
                    sum[std::size_t(triangles[a])] += visible[std::size_t(triangles[b])];
                    count[std::size_t(triangles[a])] += 1.0f;
                }
        for (std::size_t i = 0; i < n; ++i)
            if (count[i] > 0.0f) visible[i] = sum[i] / count[i];
    }
    return visible;
}

}  // namespace emoface::render
