#pragma once
// The one quad the render tests draw: four corners (counter-clockwise seen
// from +z) with their texture coordinates, as the triangles (0, 1, 2) and
// (0, 2, 3), with normals from the faces.
#include <array>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "emoface/expression/mesh.h"

namespace emoface::render::testing {

inline expression::TriMesh quad_mesh(const std::array<glm::vec3, 4>& corners, const std::array<glm::vec2, 4>& uvs) {
    expression::TriMesh m;
    m.request_vertex_normals();
    m.request_vertex_texcoords2D();
    m.request_face_normals();
    expression::TriMesh::VertexHandle v[4];
    for (int i = 0; i < 4; ++i) {
        v[i] = m.add_vertex({corners[i].x, corners[i].y, corners[i].z});
        m.set_texcoord2D(v[i], {uvs[i].x, uvs[i].y});
    }
    m.add_face(v[0], v[1], v[2]);
    m.add_face(v[0], v[2], v[3]);
    m.update_normals();
    return m;
}

}  // namespace emoface::render::testing
