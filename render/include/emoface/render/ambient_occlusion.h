#pragma once
// Static ambient occlusion per vertex, baked once per face at load from its
// rest shape (skin shading: diffuse and specular occlusion of the rig's
// ambient light, the fill and the rim; thesis shading ignores it).
//
// The bake looks at the mesh from `directions` directions spread evenly over
// the sphere (a Fibonacci lattice). From each, it rasterises the mesh on the
// CPU into an orthographic height map along the direction (texel_mm wide,
// keeping the surface nearest the light), and every vertex that faces the
// direction compares its own height with the map's: a surface above it by
// more than the bias blocks that direction, fully when it lies within
// near_mm, fading to not at all at far_mm. The occlusion is the share of
// the vertex's hemisphere that is blocked, each direction weighed by its
// cosine to the normal and by how much more the sky above (+y) lights than
// the ground below; the result is 1 - that, in [0, 1], 1 = open.
//
// The map keeps only the surface nearest the light, so the distance to an
// occluder is that of the last surface the ray crosses: a ray that enters
// the head under the chin leaves it through the face, 10 cm on. So near_mm
// is about a head's depth: within one head every occluder counts (plain
// ambient occlusion), and only far parts (a bust's shoulders seen from the
// ears) fade.
#include <vector>

#include <glm/vec3.hpp>

namespace emoface::render {

struct OcclusionSpec {
    int directions = 64;     // over the whole sphere; a vertex sees about half
    float texel_mm = 1.6f;   // height-map texel, in the mesh's units (mm for the default face)
    float bias_mm = 0.8f;    // the vertex is looked up this far above the surface, and an occluder
                             // must stand texel_mm x tan(angle to the normal) above that
    float near_mm = 120.0f;  // an occluder this close blocks fully
    float far_mm = 240.0f;   // ... and this far not at all
    float up_weight = 0.5f;  // directions weigh 1 + up_weight * y: the sky (+y) lights more than the ground
    glm::vec3 cone_axis{0.0f};       // zero: the whole sphere; else towards a light (up_weight unused)
    float cone_half_angle_deg = 0.0f;  // the light's angular radius
};

// One value per position; triangles index positions. Normals need not be
// unit length (zero: the vertex is left open, 1). Deterministic (the same
// result on any number of threads).
std::vector<float> bake_vertex_occlusion(const std::vector<glm::vec3>& positions,
                                         const std::vector<glm::vec3>& normals,
                                         const std::vector<unsigned>& triangles,
                                         const OcclusionSpec& spec = {});

}  // namespace emoface::render
