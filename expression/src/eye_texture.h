#pragma once
// The eyeball's colour (the base colour's eye tile): a sclera that is not flat
// white, an iris with radial fibres and a darker limbal ring, the pupil, the
// caruncle at the inner corner, and the upper lid's shadow baked in where it
// falls at rest.
#include <array>

#include "face_shape.h"

namespace emoface::expression::detail {

// RGB 0..1 (encoded like the rest of the base colour) at a point of the
// eyeball given by its polar angle from the front pole (radians) and its
// azimuth about the view axis (radians, 0 = towards the outer corner, pi/2 =
// up, pi = towards the nose), as the eyeball's UVs map them: the right eye's
// UVs are the left's mirrored, so both eyes have their caruncle nasally.
// The lids' rest curves come from `shape`.
std::array<double, 3> eye_colour(const FaceShape& shape, double polar, double azimuth);

}  // namespace emoface::expression::detail
