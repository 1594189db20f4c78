#include "test_face.h"

#include <cmath>

#include "emoface/fap/feature_points.h"

namespace emoface::expression::testing {

const Face& test_face() {
    static const Face face = [] {
        DefaultFaceOptions options;
        options.resolution_scale = 0.5;
        options.texture_size = 64;
        return make_default_face(data_dir() + "/face", options);
    }();
    return face;
}

const FaceRig& test_rig() {
    static const FaceRig rig(test_face());
    return rig;
}

int fp(const char* id) { return fap::feature_point_index(id); }

double distance(const Vec3d& a, const Vec3d& b) {
    return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

Vec3d to_vec(const TriMesh::Point& p) { return {p[0], p[1], p[2]}; }

}  // namespace emoface::expression::testing
