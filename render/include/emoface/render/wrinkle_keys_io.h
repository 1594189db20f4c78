#pragma once
// A folder of key wrinkle maps as `emoface wrinkles` writes it, and as an
// artist may edit it: for each key NAME.png (a tangent-space normal map, see
// expression/wrinkle_map.h for the convention) and NAME.layout.json (where the
// feature points sit in that image). NAME says what drives the key
// (face_assets.h key_weights): "neutral" (required), an emotion ("joy", the
// thesis's seven keys) or an AU term ("AU6L", "AU17"). Target
// emoface::render_io.
#include <string>
#include <vector>

#include "emoface/render/face_scene.h"

namespace emoface::render {

// Writes the keys into `folder` (which must exist): NAME.png + NAME.layout.json.
void write_wrinkle_keys(const std::string& folder, const std::vector<WrinkleKey>& keys);

// Reads every key in `folder`: neutral first, then the others by name. Every
// map must be square and of one size (256..4096); a missing neutral.png or
// layout, a PNG whose name drives no key, a size that differs or a layout
// that lacks a point some feature line needs is an emoface::InputError
// naming the file. A key's region is the box of its pixels that are not flat
// skin (128, 128, 255, 255).
std::vector<WrinkleKey> read_wrinkle_keys(const std::string& folder,
                                          const std::vector<expression::FeatureLine>& lines);

}  // namespace emoface::render
