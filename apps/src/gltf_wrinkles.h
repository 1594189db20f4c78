#pragma once
// The wrinkle key maps in a glTF export: the neutral skin's normal map as the
// skin material's normalTexture, and one image per AU key (neutral + one per
// wrinkling AU and side, as emoface renders them) with its layout and the
// index of the AU morph target that drives it, in mesh.extras.wrinkles. The
// maps need the render module (its key plan); a build without it exports
// none (available() says so).
#include <memory>
#include <string>
#include <vector>

#include <tiny_gltf.h>

#include "emoface/expression/face.h"
#include "emoface/expression/face_state.h"
#include "emoface/expression/profiles.h"
#include "emoface/expression/rig.h"

namespace emoface::apps::gltf {

bool wrinkles_available();

// glTF TANGENTs (4 floats per vertex) for the wrinkle maps' UV set `uv` (2
// floats per vertex, v down as glTF's): MikkTSpace-style frames whose
// bitangent runs up the image, as glTF's normal textures (green up) want.
// `mesh` has its vertex normals, the ones exported.
std::vector<float> wrinkle_tangents(const expression::TriMesh& mesh, const std::vector<float>& uv);

struct WrinkleExport {
    int neutral_texture = -1;  // the neutral skin's normal map (sampled with TEXCOORD_1), -1: none
    tinygltf::Value extras;    // mesh.extras.wrinkles
    std::vector<std::string> key_names;            // the AU keys, in extras' order
    std::vector<std::vector<float>> frame_weights;  // per state, per AU key
};

// Makes the keys at size x size (`rig` is lent to the key maker and given
// back), adds their images and textures to `m`; `target_names` are the
// mesh's morph targets (an AU key names the index of "AUn"); `states` the
// exported frames, whose key weights come back in frame_weights.
WrinkleExport add_wrinkle_keys(tinygltf::Model& m, const expression::Face& face,
                               std::unique_ptr<expression::FaceRig>& rig, const expression::EmotionProfiles& emotions,
                               const std::string& data_dir, int size, const std::vector<std::string>& target_names,
                               const std::vector<expression::FaceState>& states);

}  // namespace emoface::apps::gltf
