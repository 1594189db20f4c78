#include "emoface/render/tangents.h"

#include <cmath>

#include <glm/geometric.hpp>

#include "emoface/common/error.h"

namespace emoface::render {
namespace {

glm::vec3 to_glm(const OpenMesh::Vec3f& v) { return {v[0], v[1], v[2]}; }

// The component of v perpendicular to the unit vector n.
glm::vec3 reject(const glm::vec3& v, const glm::vec3& n) { return v - n * glm::dot(n, v); }

bool usable(const glm::vec3& v, float min_length2) {
    const float l2 = glm::dot(v, v);
    return std::isfinite(l2) && l2 > min_length2;
}

// Any unit vector perpendicular to the unit vector n.
glm::vec3 any_perpendicular(const glm::vec3& n) {
    const glm::vec3 axis = std::fabs(n.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
    return glm::normalize(glm::cross(glm::cross(n, axis), n));
}

// A UV triangle whose edges are nearly parallel (sine of their angle below
// this) has no usable tangent direction: MikkTSpace's "degenerate" faces.
constexpr float kMinUvSine = 1e-6f;
constexpr float kMinLength2 = 1e-24f;

}  // namespace

void TangentFrames::compute(const expression::TriMesh& mesh) {
    if (!mesh.has_vertex_texcoords2D())
        fail("render: TangentFrames::compute(): the mesh has no vertex texcoords2D");
    uv_scratch_.resize(mesh.n_vertices());
    for (const auto vh : mesh.vertices()) {
        const auto& t = mesh.texcoord2D(vh);
        uv_scratch_[vh.idx()] = {t[0], t[1]};
    }
    compute(mesh, uv_scratch_);
}

void TangentFrames::compute(const expression::TriMesh& mesh, const std::vector<glm::vec2>& uvs) {
    const std::size_t n = mesh.n_vertices();
    if (uvs.size() != n)
        fail("render: TangentFrames::compute(): expected one UV per vertex ({}), got {}", n,
             uvs.size());
    if (!mesh.has_vertex_normals())
        fail("render: TangentFrames::compute(): the mesh has no vertex normals");

    tangents_.resize(n);
    tangent_sum_.assign(n, glm::vec3(0.0f));
    bitangent_sum_.assign(n, glm::vec3(0.0f));
    // Signed handedness weight per vertex, kept in tangents_[i].w meanwhile.
    for (auto& t : tangents_) t = glm::vec4(0.0f);

    for (const auto fh : mesh.faces()) {
        int idx[3];
        int k = 0;
        for (const auto vh : mesh.fv_range(fh)) {
            if (k == 3) break;
            idx[k++] = vh.idx();
        }
        if (k != 3) continue;
        const glm::vec3 p[3] = {to_glm(mesh.point(mesh.vertex_handle(idx[0]))),
                                to_glm(mesh.point(mesh.vertex_handle(idx[1]))),
                                to_glm(mesh.point(mesh.vertex_handle(idx[2])))};
        const glm::vec2 uv[3] = {uvs[idx[0]], uvs[idx[1]], uvs[idx[2]]};
        const glm::vec3 e1 = p[1] - p[0], e2 = p[2] - p[0];
        const glm::vec2 d1 = uv[1] - uv[0], d2 = uv[2] - uv[0];
        const float det = d1.x * d2.y - d2.x * d1.y;
        const float uv_scale = std::sqrt(glm::dot(d1, d1) * glm::dot(d2, d2));
        if (!(std::fabs(det) > kMinUvSine * uv_scale)) continue;  // also rejects NaN UVs
        // dp/du and dp/dv of the face, up to the positive factor 1/|det|.
        const float s = det > 0 ? 1.0f : -1.0f;
        const glm::vec3 face_t = (e1 * d2.y - e2 * d1.y) * s;
        const glm::vec3 face_b = (e2 * d1.x - e1 * d2.x) * s;
        if (!usable(face_t, kMinLength2) || !usable(face_b, kMinLength2)) continue;

        for (int c = 0; c < 3; ++c) {
            const int v = idx[c];
            const glm::vec3 a = p[(c + 1) % 3] - p[c], b = p[(c + 2) % 3] - p[c];
            if (!usable(a, kMinLength2) || !usable(b, kMinLength2)) continue;
            const float angle = std::acos(
                glm::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0f, 1.0f));
            const glm::vec3 nv = to_glm(mesh.normal(mesh.vertex_handle(v)));
            if (!usable(nv, kMinLength2)) continue;
            const glm::vec3 nn = glm::normalize(nv);
            glm::vec3 t = reject(face_t, nn), bt = reject(face_b, nn);
            if (!usable(t, kMinLength2) || !usable(bt, kMinLength2)) continue;
            t = glm::normalize(t);
            bt = glm::normalize(bt);
            // Handedness of this corner. Accumulating w*T instead of T keeps
            // the tangents of mirrored halves (u runs the other way) from
            // cancelling where they meet; the vertex then takes the dominant w.
            const float w = glm::dot(glm::cross(nn, t), bt) < 0 ? -1.0f : 1.0f;
            tangent_sum_[v] += angle * w * t;
            bitangent_sum_[v] += angle * bt;
            tangents_[v].w += angle * w;
        }
    }

    fallback_count_ = 0;
    for (const auto vh : mesh.vertices()) {
        const int v = vh.idx();
        const glm::vec3 nv = to_glm(mesh.normal(vh));
        const glm::vec3 nn = usable(nv, kMinLength2) ? glm::normalize(nv) : glm::vec3(0, 0, 1);
        const float w = tangents_[v].w < 0 ? -1.0f : 1.0f;
        glm::vec3 t = reject(tangent_sum_[v], nn);
        if (usable(t, kMinLength2)) {
            t = w * glm::normalize(t);
        } else {
            ++fallback_count_;
            const glm::vec3 b = reject(bitangent_sum_[v], nn);
            // B = w cross(N, T) for an orthonormal frame, hence T = w cross(B, N).
            t = usable(b, kMinLength2) ? w * glm::normalize(glm::cross(b, nn))
                                       : any_perpendicular(nn);
        }
        tangents_[v] = glm::vec4(t, usable(t, kMinLength2) ? w : 1.0f);
    }
}

}  // namespace emoface::render
