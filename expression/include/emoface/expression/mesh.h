#pragma once
// The triangle mesh type every face uses (default face, Candide-3, user OBJ),
// shared by expression/ (which builds and deforms it) and render/ (which
// computes tangent frames on it and draws it).
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

namespace emoface::expression {

// Points and normals are float Vec3f, texture coordinates Vec2f.
// Faces built by expression/ have vertex normals and vertex texcoords2D
// (the fixed base-colour UVs) requested.
using TriMesh = OpenMesh::TriMesh_ArrayKernelT<>;

}  // namespace emoface::expression
