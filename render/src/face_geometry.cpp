#include "emoface/render/face_geometry.h"

#include "emoface/common/error.h"
#include "emoface/common/parallel.h"
#include "mesh_triangles.h"

namespace emoface::render {
namespace {

// CSR of the items of `count` lists: item i belongs to list owner(i).
template <class Owner>
void csr(int lists, int items, const Owner& owner, std::vector<int>& start, std::vector<int>& entries) {
    start.assign(std::size_t(lists) + 1, 0);
    for (int i = 0; i < items; ++i) ++start[std::size_t(owner(i)) + 1];
    for (int l = 0; l < lists; ++l) start[std::size_t(l) + 1] += start[std::size_t(l)];
    std::vector<int> fill(start.begin(), start.end() - 1);
    entries.resize(std::size_t(items));
    for (int i = 0; i < items; ++i) entries[std::size_t(fill[std::size_t(owner(i))]++)] = i;
}

}  // namespace

FaceGeometry::FaceGeometry(const expression::FaceRig& rig, const expression::TriMesh& mesh,
                           std::vector<GeometryPart> parts, const std::array<float, 4>& box)
    : rig_(rig), parts_(std::move(parts)), box_(box) {
    const int n = int(mesh.n_vertices());
    if (rig.vertex_count() != n)
        fail<InputError>("render: FaceGeometry: expected a mesh of the rig's {} vertices, found {}", rig.vertex_count(), n);
    triangles_ = triangle_indices(mesh);
    csr(n, int(triangles_.size()), [&](int c) { return triangles_[std::size_t(c)]; }, vertex_face_start_, vertex_faces_);
    for (int& c : vertex_faces_) c /= 3;  // corners to faces: each face once per vertex it has

    bool any_fixed = false;
    for (const GeometryPart& p : parts_) any_fixed |= !p.fixed_uvs.empty();
    for (std::size_t p = 0; p < parts_.size(); ++p) {
        const GeometryPart& part = parts_[p];
        const int first = int(part_full_.size());
        const int size = int(part.full_index.size());
        if (!part.fixed_uvs.empty() && int(part.fixed_uvs.size()) != size)
            fail("render: FaceGeometry: part {} has {} fixed UVs for {} vertices", p, part.fixed_uvs.size(), size);
        if (any_fixed && part.frames && part.fixed_uvs.empty())
            fail("render: FaceGeometry: part {} has frames but no fixed UVs while another part has them", p);
        part_first_.push_back(first);
        part_frames_.push_back(part.frames ? 1 : 0);
        for (int v : part.full_index) {
            if (v < 0 || v >= n) fail("render: FaceGeometry: part {} names vertex {} of {}", p, v, n);
            part_full_.push_back(v);
            part_of_.push_back(int(p));
        }
        for (int t : part.triangles) {
            if (t < 0 || t >= size) fail("render: FaceGeometry: part {} has a triangle on vertex {} of {}", p, t, size);
            part_triangles_.push_back(first + t);
        }
        for (int i = 0; i < size; ++i) {
            const glm::vec2 uv = part.fixed_uvs.empty() ? glm::vec2(0.0f) : part.fixed_uvs[std::size_t(i)];
            if (any_fixed) fixed_uvs_.insert(fixed_uvs_.end(), {uv.x, uv.y});
        }
    }
    part_first_.push_back(int(part_full_.size()));
    csr(int(part_full_.size()), int(part_triangles_.size()), [&](int c) { return part_triangles_[std::size_t(c)]; },
        corner_start_, corners_);
}

geometry_kernel::GeometryView FaceGeometry::view() const {
    geometry_kernel::GeometryView g;
    g.full_vertices = int(vertex_face_start_.size()) - 1;
    g.part_vertices = int(part_full_.size());
    g.triangles = triangles_.data();
    g.vertex_face_start = vertex_face_start_.data();
    g.vertex_faces = vertex_faces_.data();
    g.part_full = part_full_.data();
    g.part_of = part_of_.data();
    g.part_first = part_first_.data();
    g.part_triangles = part_triangles_.data();
    g.corner_start = corner_start_.data();
    g.corners = corners_.data();
    g.part_frames = part_frames_.data();
    g.fixed_uvs = fixed_uvs_.empty() ? nullptr : fixed_uvs_.data();
    for (int i = 0; i < 4; ++i) g.box[i] = box_[std::size_t(i)];
    return g;
}

void FaceGeometry::compute(const expression::RigFrame& frame, std::vector<std::vector<float>>& shape,
                           std::vector<std::vector<float>>& frame_out) {
    const expression::RigView r = rig_.view();
    const geometry_kernel::GeometryView g = view();
    positions_.resize(std::size_t(r.vertex_count) * 3);
    float* pos = positions_.data();
    // Chunks of fixed size: the result does not depend on the threads.
    parallel_for(r.vertex_count, 4096, [&](int begin, int end) {
        for (int v = begin; v < end; ++v) {
            const expression::rig_kernel::P3 p = expression::rig_kernel::position(r, frame, v);
            pos[3 * v] = p.x, pos[3 * v + 1] = p.y, pos[3 * v + 2] = p.z;
        }
    });
    const int faces = int(triangles_.size() / 3), part_triangles = int(part_triangles_.size() / 3);
    face_normals_.resize(std::size_t(faces));
    triangle_frames_.resize(std::size_t(part_triangles));
    parallel_for(faces, 4096, [&](int begin, int end) {
        for (int f = begin; f < end; ++f) face_normals_[std::size_t(f)] = geometry_kernel::face_pass(g, pos, f);
    });
    parallel_for(part_triangles, 4096, [&](int begin, int end) {
        for (int t = begin; t < end; ++t) triangle_frames_[std::size_t(t)] = geometry_kernel::part_triangle_pass(g, pos, t);
    });
    shape.resize(parts_.size());
    frame_out.resize(parts_.size());
    for (std::size_t p = 0; p < parts_.size(); ++p) {
        const int size = part_size(int(p));
        shape[p].resize(std::size_t(size) * 6);
        if (parts_[p].frames) frame_out[p].resize(std::size_t(size) * 6);
        else frame_out[p].clear();
        float* s = shape[p].data();
        float* f = parts_[p].frames ? frame_out[p].data() : nullptr;
        const int first = part_first_[p];
        parallel_for(size, 4096, [&](int begin, int end) {
            for (int i = begin; i < end; ++i)
                geometry_kernel::part_vertex_pass(g, pos, face_normals_.data(), triangle_frames_.data(), first + i,
                                                  s + 6 * i, f ? f + 6 * i : nullptr);
        });
    }
}

}  // namespace emoface::render
