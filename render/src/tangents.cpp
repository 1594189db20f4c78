#include "emoface/render/tangents.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>

#include <glm/geometric.hpp>

#include "emoface/common/constants.h"
#include "emoface/common/error.h"
#include "emoface/common/parallel.h"

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

// acos to within 7e-5 rad (Abramowitz and Stegun 4.4.45): the angle only
// weights a corner's share, and std::acos is the loop's largest cost.
float fast_acos(float x) {
    x = glm::clamp(x, -1.0f, 1.0f);
    const float a = std::fabs(x);
    float r = ((-0.0187293f * a + 0.0742610f) * a - 0.2121144f) * a + 1.5707288f;
    r *= std::sqrt(1.0f - a);
    return x < 0 ? kPiF - r : r;
}

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

void TangentFrames::build_topology(const expression::TriMesh& mesh) {
    const std::size_t n = mesh.n_vertices();
    triangles_.clear();
    triangles_.reserve(mesh.n_faces() * 3);
    for (const auto fh : mesh.faces()) {
        int idx[3], k = 0;
        for (const auto vh : mesh.fv_range(fh)) {
            if (k < 3) idx[k] = vh.idx();
            ++k;
        }
        if (k == 3) triangles_.insert(triangles_.end(), idx, idx + 3);
    }
    corner_start_.assign(n + 1, 0);
    for (const int v : triangles_) ++corner_start_[std::size_t(v) + 1];
    for (std::size_t v = 0; v < n; ++v) corner_start_[v + 1] += corner_start_[v];
    corners_.resize(triangles_.size());
    std::vector<int> fill(corner_start_.begin(), corner_start_.end() - 1);
    for (std::size_t c = 0; c < triangles_.size(); ++c)
        corners_[std::size_t(fill[std::size_t(triangles_[c])]++)] = int(c);
    topology_vertices_ = n;
    topology_faces_ = mesh.n_faces();
}

void TangentFrames::compute(const expression::TriMesh& mesh, const std::vector<glm::vec2>& uvs) {
    const std::size_t n = mesh.n_vertices();
    if (uvs.size() != n)
        fail("render: TangentFrames::compute(): expected one UV per vertex ({}), got {}", n,
             uvs.size());
    if (!mesh.has_vertex_normals())
        fail("render: TangentFrames::compute(): the mesh has no vertex normals");
    if (triangles_.empty() || topology_vertices_ != n || topology_faces_ != mesh.n_faces())
        build_topology(mesh);

    const auto* points = reinterpret_cast<const OpenMesh::Vec3f*>(mesh.points());
    const auto* normals = reinterpret_cast<const OpenMesh::Vec3f*>(mesh.vertex_normals());
    const std::size_t faces = triangles_.size() / 3;
    unit_normals_.resize(n);
    face_t_.resize(faces);
    face_b_.resize(faces);
    corner_angle_.resize(faces * 3);
    tangents_.resize(n);

    // Large meshes are split over the shared pool; chunks of fixed size keep
    // the work per wake-up large and the result independent of the threads.
    constexpr std::size_t kChunk = 4096;
    auto parallel = [](std::size_t count, const std::function<void(std::size_t, std::size_t)>& body) {
        parallel_for(int(count), int(kChunk), [&](int begin, int end) { body(std::size_t(begin), std::size_t(end)); });
    };

    // Pass 1, per triangle: dp/du, dp/dv (up to a positive factor) and the
    // corner angles; zero vectors mark faces without a usable frame.
    parallel(faces, [&](std::size_t begin, std::size_t end) {
        for (std::size_t f = begin; f < end; ++f) {
            const int* idx = &triangles_[3 * f];
            face_t_[f] = face_b_[f] = glm::vec3(0.0f);
            const glm::vec3 p[3] = {to_glm(points[idx[0]]), to_glm(points[idx[1]]),
                                    to_glm(points[idx[2]])};
            const glm::vec2 uv[3] = {uvs[idx[0]], uvs[idx[1]], uvs[idx[2]]};
            const glm::vec3 e1 = p[1] - p[0], e2 = p[2] - p[0];
            const glm::vec2 d1 = uv[1] - uv[0], d2 = uv[2] - uv[0];
            const float det = d1.x * d2.y - d2.x * d1.y;
            const float uv_scale = std::sqrt(glm::dot(d1, d1) * glm::dot(d2, d2));
            if (!(std::fabs(det) > kMinUvSine * uv_scale)) continue;  // also rejects NaN UVs
            const float s = det > 0 ? 1.0f : -1.0f;
            const glm::vec3 t = (e1 * d2.y - e2 * d1.y) * s;
            const glm::vec3 b = (e2 * d1.x - e1 * d2.x) * s;
            if (!usable(t, kMinLength2) || !usable(b, kMinLength2)) continue;
            glm::vec3 edge[3] = {p[1] - p[0], p[2] - p[1], p[0] - p[2]};
            bool edges_ok = true;
            for (auto& e : edge) {
                const float l2 = glm::dot(e, e);
                if (!(l2 > kMinLength2)) edges_ok = false;
                e /= std::sqrt(l2);
            }
            if (!edges_ok) continue;  // a zero-length edge: no corner angles
            face_t_[f] = t;
            face_b_[f] = b;
            // Corner c lies between the edge leaving it and the one arriving.
            for (int c = 0; c < 3; ++c)
                corner_angle_[3 * f + c] = fast_acos(-glm::dot(edge[c], edge[(c + 2) % 3]));
        }
    });

    // Pass 2, per vertex: gather its corners, orthogonalise, pick w.
    std::atomic<std::size_t> fallbacks{0};
    parallel(n, [&](std::size_t begin, std::size_t end) {
        std::size_t local_fallbacks = 0;
        for (std::size_t v = begin; v < end; ++v) {
            const glm::vec3 nv = to_glm(normals[v]);
            const bool has_normal = usable(nv, kMinLength2);
            const glm::vec3 nn = has_normal ? nv / std::sqrt(glm::dot(nv, nv)) : glm::vec3(0, 0, 1);
            glm::vec3 t_sum(0.0f), b_sum(0.0f);
            float w_sum = 0.0f;
            if (has_normal)
                for (int k = corner_start_[v]; k < corner_start_[v + 1]; ++k) {
                    const int corner = corners_[std::size_t(k)];
                    const std::size_t f = std::size_t(corner) / 3;
                    glm::vec3 t = reject(face_t_[f], nn), bt = reject(face_b_[f], nn);
                    const float lt = glm::dot(t, t), lb = glm::dot(bt, bt);
                    if (!(lt > kMinLength2) || !(lb > kMinLength2)) continue;
                    t /= std::sqrt(lt);
                    bt /= std::sqrt(lb);
                    // Handedness of this corner. Accumulating w*T instead of T
                    // keeps the tangents of mirrored halves (u runs the other
                    // way) from cancelling where they meet; the vertex then
                    // takes the dominant w.
                    const float w = glm::dot(glm::cross(nn, t), bt) < 0 ? -1.0f : 1.0f;
                    const float angle = corner_angle_[std::size_t(corner)];
                    t_sum += angle * w * t;
                    b_sum += angle * bt;
                    w_sum += angle * w;
                }
            const float w = w_sum < 0 ? -1.0f : 1.0f;
            glm::vec3 t = reject(t_sum, nn);
            if (usable(t, kMinLength2)) {
                t = w * glm::normalize(t);
            } else {
                ++local_fallbacks;
                const glm::vec3 b = reject(b_sum, nn);
                // B = w cross(N, T) for an orthonormal frame, hence T = w cross(B, N).
                t = usable(b, kMinLength2) ? w * glm::normalize(glm::cross(b, nn))
                                           : any_perpendicular(nn);
            }
            tangents_[v] = glm::vec4(t, usable(t, kMinLength2) ? w : 1.0f);
        }
        fallbacks += local_fallbacks;
    });
    fallback_count_ = fallbacks.load();
}

}  // namespace emoface::render
