#pragma once
// The built-in face, generated procedurally from human-editable parameters in
// data/face/face.json (docs/FACE.md describes them): a closed head with neck
// stump, eyeballs in their sockets under eyelids that close, a nose with
// nostrils, lips that part over a mouth cavity with teeth and a tongue, ears,
// and a procedural base-colour image (skin, lips, brows, lashes, hair, eyes).
// All 84 MPEG-4 feature points are located on it.
#include <string>

#include "emoface/expression/face.h"

namespace emoface::expression {

struct DefaultFaceOptions {
    // Multiplies the mesh resolution from face.json (rows and columns); 0.5
    // gives about a quarter of the vertices, handy in tests.
    double resolution_scale = 1.0;
    // Side of the square base-colour image; 0 takes face.json's
    // texture.size. Small values keep tests fast.
    int texture_size = 0;
};

// Builds the default face from `params_dir`/face.json (data/face). Throws
// emoface::InputError when the file is missing, is not JSON, has an unknown
// key or a value of the wrong type (the message names the key).
Face make_default_face(const std::string& params_dir, const DefaultFaceOptions& options = {});

}  // namespace emoface::expression
