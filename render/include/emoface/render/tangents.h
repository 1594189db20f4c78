#pragma once
// Per-vertex tangent frames for tangent-space normal mapping, following the
// MikkTSpace conventions: the tangent is accumulated per face corner (weighted
// by the corner's angle, projected into the vertex normal's plane), then
// orthogonalised against the normal (Gram-Schmidt); w holds the handedness, so
// the shader rebuilds the bitangent as w * cross(N, T).
//
// The arithmetic is geometry_kernel.h's, which the GPU geometry driver runs
// too. The frames are recomputed every frame on the deformed mesh: the projective
// layout's wrinkle UVs change every frame, and with the anchored layout's
// fixed UVs the surface still bends (DESIGN.md "One frame"). TangentFrames
// keeps its buffers between calls and does not allocate once the vertex
// count is stable. UVs are taken as given, v down the image as the wrinkle
// maps' rows run; a caller with OBJ-style UVs (v up) passes (u, 1 - v), or the
// frames' bitangent points the opposite way of the maps' green.
#include <cstddef>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "emoface/expression/mesh.h"
#include "emoface/render/geometry_kernel.h"

namespace emoface::render {

class TangentFrames {
public:
    // Computes one tangent per vertex of `mesh` for the UV set `uvs` (one UV
    // per vertex, indexed like the mesh's vertices). Uses the mesh's current
    // points and vertex normals (the mesh must have vertex normals, updated
    // for its current shape). Faces whose UV triangle has no area (degenerate
    // UVs) contribute nothing; a vertex left with no usable direction gets a
    // tangent perpendicular to its normal, derived from the accumulated
    // bitangent when there is one, else an arbitrary one, with w = +1.
    // Throws emoface::Error when uvs.size() != mesh.n_vertices() or the mesh
    // has no vertex normals.
    void compute(const expression::TriMesh& mesh, const std::vector<glm::vec2>& uvs);

    // Same with the mesh's own per-vertex texcoords2D as the UV set, taken
    // as stored (an OBJ's v runs up: its frames suit a map whose rows run up).
    void compute(const expression::TriMesh& mesh);

    const std::vector<glm::vec4>& tangents() const { return tangents_; }

    // How many vertices got the fallback tangent in the last compute() (all
    // their faces had degenerate UVs or a tangent along the normal).
    std::size_t fallback_count() const { return fallback_count_; }

    // The triangle list is read from the mesh once and kept while the mesh's
    // vertex and face counts stay the same (a face's shape changes every
    // frame, its connectivity does not). Call this after changing the
    // connectivity of a mesh without changing those counts.
    void invalidate_topology() { triangles_.clear(); }

private:
    void build_topology(const expression::TriMesh& mesh);

    // Topology: 3 vertex indices per triangle, and each vertex's corners
    // (3 * triangle + corner) in CSR form, so the per-vertex sums are
    // gathered in a fixed order (the same result on any thread count).
    std::vector<int> triangles_;
    std::vector<int> corner_start_, corners_;
    std::size_t topology_vertices_ = 0, topology_faces_ = 0;
    // Per frame: each face's dp/du, dp/dv (zero when the face is
    // degenerate) and corner angles.
    std::vector<geometry_kernel::FaceFrame> face_frames_;
    std::vector<glm::vec4> tangents_;
    std::vector<glm::vec2> uv_scratch_;
    std::size_t fallback_count_ = 0;
};

}  // namespace emoface::render
