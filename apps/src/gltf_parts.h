#pragma once
// The face's parts as glTF primitives, each with its own material: skin,
// eyes, teeth (with the gums), mouth interior (cavity and tongue), lashes.
// The primitives share the vertex attributes and morph targets (glTF allows
// one accessor in several primitives) and differ in their triangles.
#include <cstdint>
#include <string>
#include <vector>

#include "emoface/expression/face.h"
#include "emoface/expression/rig_kernel.h"

namespace emoface::apps::gltf {

struct PartMaterial {
    std::string name;
    double roughness;       // glTF's perceptual roughness
    const char* why;        // the reason for the roughness, in the material's extras
    std::vector<std::uint32_t> triangles;  // vertex indices, 3 per triangle
};

// The face's triangles by part, parts without triangles left out. A triangle
// is a lash's when a vertex of it rides on a lid margin (the rig's lash
// strands), else its first vertex's VertexPart decides; of the mouth's parts
// the largest connected piece of each is the cavity, the smaller ones (the
// default face's crowns and gum bands) the teeth.
std::vector<PartMaterial> split_into_parts(const expression::Face& face, const expression::RigView& rig);

}  // namespace emoface::apps::gltf
