#pragma once
// The eyeball's colour (the base colour's eye tile): a sclera that is not flat
// white, an iris with radial fibres and a darker limbal ring, the pupil, and
// the upper lid's shadow baked in where it falls at rest.
#include <array>

#include "face_shape.h"

namespace emoface::expression::detail {

// RGB 0..1 (encoded like the rest of the base colour) at a point of the
// eyeball given by its polar angle from the front pole (radians) and its
// azimuth about the view axis (radians, 0 = the face's left, pi/2 = up), as
// the eyeball's UVs map them. The lids' rest curves come from `shape`.
std::array<double, 3> eye_colour(const FaceShape& shape, double polar, double azimuth);

}  // namespace emoface::expression::detail
