#include "emoface/render/tangents.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>

#include <glm/geometric.hpp>

#include "emoface/common/constants.h"
#include "emoface/common/error.h"
#include "emoface/common/parallel.h"
#include "emoface/render/geometry_kernel.h"
#include "mesh_triangles.h"

namespace emoface::render {
namespace {

namespace gk = geometry_kernel;

gk::V3 to_v3(const OpenMesh::Vec3f& v) { return {v[0], v[1], v[2]}; }

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
    triangles_ = triangle_indices(mesh);
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
    face_frames_.resize(faces);
    tangents_.resize(n);

    // Large meshes are split over the shared pool; chunks of fixed size keep
    // the work per wake-up large and the result independent of the threads.
    constexpr int kChunk = 4096;

    // Pass 1, per triangle: its frame (geometry_kernel::face_frame).
    parallel_for(int(faces), kChunk, [&](int begin, int end) {
        for (int f = begin; f < end; ++f) {
            const int* idx = &triangles_[3 * std::size_t(f)];
            const gk::V3 p[3] = {to_v3(points[idx[0]]), to_v3(points[idx[1]]), to_v3(points[idx[2]])};
            const gk::V2 uv[3] = {{uvs[idx[0]].x, uvs[idx[0]].y}, {uvs[idx[1]].x, uvs[idx[1]].y},
                                  {uvs[idx[2]].x, uvs[idx[2]].y}};
            face_frames_[std::size_t(f)] = gk::face_frame(p, uv);
        }
    });

    // Pass 2, per vertex: gather its corners (geometry_kernel::vertex_tangent).
    std::atomic<std::size_t> fallbacks{0};
    parallel_for(int(n), kChunk, [&](int begin, int end) {
        std::size_t local_fallbacks = 0;
        for (int v = begin; v < end; ++v) {
            const int first = corner_start_[std::size_t(v)];
            auto corner = [&](int k, gk::V3& t, gk::V3& b, float& angle) {
                const int c = corners_[std::size_t(first + k)];
                const gk::FaceFrame& f = face_frames_[std::size_t(c / 3)];
                t = f.t;
                b = f.b;
                angle = f.angle[c % 3];
            };
            bool fallback = false;
            const gk::V4 t = gk::vertex_tangent(to_v3(normals[v]), corner_start_[std::size_t(v) + 1] - first, corner,
                                                &fallback);
            tangents_[std::size_t(v)] = glm::vec4(t.x, t.y, t.z, t.w);
            local_fallbacks += fallback;
        }
        fallbacks += local_fallbacks;
    });
    fallback_count_ = fallbacks.load();
}

}  // namespace emoface::render
