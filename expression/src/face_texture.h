#pragma once
// Paints the default face's base-colour image by rasterising every triangle
// in texture space and colouring each texel from the neutral 3D position it
// covers (skin, lips, brows, lashes, hair, nostrils) or from its place in a
// part's tile (eyeball, mouth cavity, teeth, tongue). Hair, brow hairs and
// lip lines are painted at the neutral position they cover, so they travel
// with the skin (its UVs) when it moves.
//
// Alpha is not coverage: it is the region's roughness scale for the skin
// shading model (render/skin_shading.h; face.json albedo.roughness): 1 on
// most skin and on the tiles, lower on the T-zone, lips, lid margins and the
// tear meniscus.
#include <vector>

#include "emoface/expression/face.h"
#include "face_shape.h"

namespace emoface::expression::detail {

// Texture atlas: the skin takes v in [kSkinV0, 1]; the bottom strip holds
// square tiles, each kTile wide, in this order.
constexpr double kSkinV0 = 0.25;
constexpr double kTile = 0.25;
enum class Tile { Eye = 0, Cavity = 1, Teeth = 2, Tongue = 3 };
inline double tile_u0(Tile t) { return static_cast<int>(t) * kTile; }

// Texels in the bottom strip are coloured by the tile they fall in, the
// others as skin from the interpolated neutral position.
Image paint_base_colour(const FaceShape& shape, const TriMesh& mesh, int size);

}  // namespace emoface::expression::detail
