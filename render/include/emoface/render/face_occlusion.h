#pragma once
// The baked ambient occlusion of a face's rest shape (ambient_occlusion.h),
// aware that the mouth opens away from it and that the lids move. Three bakes:
// - the skin, the whole head but the lashes occluding (strands far thinner
//   than the bake's texel, which it would rasterise as a solid visor over
//   the lid); the lids keep only a share of it: the upper lid from its
//   margin over the brow's underside (its skin moves most of all, out from
//   under the brow when the brows and lids rise, and carried its rest shade
//   there as a dark band) and the lower lid over its furrow (its rest
//   shade, with the key's contact shadow, ringed the eye in a dark smudge);
// - the lips (around the mouth slit, from the inner lip contour out past the
//   vermilion borders, found from feature points 2.2-2.5, 8.1 and 8.2): at
//   rest each lip hides the other's inner face, which would show dark when
//   the mouth opens; they are baked again without the lips and the mouth
//   interior among the occluders (the nose, cheeks and chin stay), and the
//   brighter of the two fades in over the lips;
// - the mouth interior (cavity, teeth, gums, tongue: the non-skin, non-eye
//   parts), which the skin bake sees only through the closed slit: baked on
//   its own at a finer texel (its cavity shades its back, the teeth each
//   other), then dimmed with the depth behind where the lips meet, standing
//   for the lips and cheeks over an open mouth.
// Eyeball vertices get the whole-head bake (the renderer leaves them open).
#include <vector>

#include <glm/vec3.hpp>

#include "emoface/expression/face.h"

namespace emoface::render {

// One value per vertex of `mesh` in [0, 1], 1 = open. `mesh` is the face's
// mesh with vertex normals; a face without parts or lip feature points gets
// the plain whole-mesh bake.
std::vector<float> bake_face_occlusion(const expression::TriMesh& mesh, const expression::Face& face);

// The share of a soft light that reaches each vertex of the rest shape: its
// cast shadows (the nose's on the cheek and lip, the brow's in the socket,
// the jaw's on the neck), the light seen as a disc of `half_angle_deg`
// around `toward_light` (mesh space) from `samples` directions. The same
// bake as above (the lashes cast nothing, the lids keep a share, the lips
// see past each other), but for the mouth interior, left open (1); then
// smoothed over the surface a little (the height maps' texels stair-step a
// shadow's edge).
std::vector<float> bake_face_light_visibility(const expression::TriMesh& mesh, const expression::Face& face,
                                              const glm::vec3& toward_light, float half_angle_deg, int samples);

}  // namespace emoface::render
