#include "emoface/render/face_occlusion.h"

#include <algorithm>
#include <cmath>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "emoface/fap/feature_points.h"
#include "emoface/render/ambient_occlusion.h"

namespace emoface::render {
namespace {

bool is_interior(expression::VertexPart p) {
    return p == expression::VertexPart::MouthUpper || p == expression::VertexPart::MouthLower ||
           p == expression::VertexPart::Tongue;
}

}  // namespace

std::vector<float> bake_face_occlusion(const expression::TriMesh& mesh, const expression::Face& face) {
    const std::size_t n = mesh.n_vertices();
    std::vector<glm::vec3> positions(n), normals(n);
    for (const auto vh : mesh.vertices()) {
        const auto& p = mesh.point(vh);
        const auto& nv = mesh.normal(vh);
        positions[std::size_t(vh.idx())] = {p[0], p[1], p[2]};
        normals[std::size_t(vh.idx())] = {nv[0], nv[1], nv[2]};
    }
    std::vector<unsigned> triangles;
    triangles.reserve(mesh.n_faces() * 3);
    for (const auto fh : mesh.faces()) {
        unsigned v[3];
        int k = 0;
        for (const auto vh : mesh.fv_range(fh))
            if (k < 3) v[k++] = unsigned(vh.idx());
        if (k == 3) triangles.insert(triangles.end(), v, v + 3);
    }
    std::vector<float> open = bake_vertex_occlusion(positions, normals, triangles);

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

    auto point = [&](const char* id, glm::vec3& p) {
        const auto& fp = face.feature_points[std::size_t(fap::feature_point_index(id))];
        if (!fp.present) return false;
        p = glm::vec3(float(fp.position[0]), float(fp.position[1]), float(fp.position[2]));
        return true;
    };
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
                        OcclusionSpec{});
        for (std::size_t v = 0; v < n; ++v)
            if (lip[v] > 0.0f) open[v] = glm::mix(open[v], std::max(open[v], lips_open[v]), lip[v]);
    }

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

}  // namespace emoface::render
