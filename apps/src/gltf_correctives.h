#pragma once
// Corrective morph targets for the rig's motion that no FAP target carries.
//
// The FAP targets are the rig's motion per FAP, and most of the rig is linear
// in the FAPs, but not all of it: a lid vertex that reaches the eyeball is
// put back on its surface (z = the sphere's height above its x, y: a square
// root, and a kink where contact begins), a lash turns by the angle its
// margin vertex turned about the eyeball (an atan2 and a rotation), the pupil
// dilates along the sphere (asin), the mouth corners' inner and outer points
// give way to each other beyond a distance (a norm), the tongue rolls by a
// sine. No fixed set of targets with weights linear in the FAPs can carry
// these, and no joint can either (the slide keeps x, y and sets z per
// vertex). What glTF can carry exactly is the motion at the poses that are
// exported: the remainder at each pose (the rig minus the FAP targets) lies
// in a space of few dimensions, because few FAPs drive it, so a handful of
// targets spans it at every frame of an animation.
#include <vector>

namespace emoface::apps::gltf {

struct Correctives {
    // Each a displacement of every vertex (3 floats per vertex).
    std::vector<std::vector<float>> targets;
    // Per pose, one weight per target.
    std::vector<std::vector<float>> weights;
    double worst_before = 0;  // the largest vertex remainder with no corrective
    double worst_left = 0;    // ... and what the targets leave of it
};

// `remainders[k]`: pose k's displacement that the targets must carry at
// `vertices` (3 floats each; the other vertices of the `vertex_count` need
// none). Greedy column-pivoted Gram-Schmidt: the pose whose
// remainder has the farthest-off vertex becomes the next target direction,
// every pose's remainder loses its part along it, until no vertex of any pose
// is off by more than `tolerance` or `max_targets` are made. The remainders
// are consumed.
Correctives fit_correctives(const std::vector<int>& vertices, std::vector<std::vector<float>> remainders,
                            int vertex_count, double tolerance, int max_targets);

}  // namespace emoface::apps::gltf
