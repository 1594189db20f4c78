#pragma once
// A folder of key wrinkle maps as `emoface wrinkles` writes it, and as an
// artist may edit it: for each key (neutral, joy, sadness, anger, fear,
// disgust, surprise) NAME.png (a tangent-space normal map, see
// expression/wrinkle_map.h for the convention) and NAME.layout.json (where the
// feature points sit in that image). Target emoface::render_io.
#include <string>
#include <vector>

#include "emoface/render/face_scene.h"

namespace emoface::render {

// Writes the keys into `folder` (which must exist): NAME.png + NAME.layout.json.
void write_wrinkle_keys(const std::string& folder, const std::vector<WrinkleKey>& keys);

// Reads the seven keys from `folder`, in expression::WrinkleKey order. Every
// map must be square and of one size (256..4096); a missing file, a size that
// differs or a layout that lacks a point some feature line needs is an
// emoface::InputError naming the file.
std::vector<WrinkleKey> read_wrinkle_keys(const std::string& folder,
                                          const std::vector<expression::FeatureLine>& lines);

}  // namespace emoface::render
