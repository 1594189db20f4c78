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

std::optional<FrontCrossing> front_crossing(const TriMesh::Point& a, const TriMesh::Point& b, const TriMesh::Point& c,
                                            double x, double y) {
    const double d = (b[1] - c[1]) * (a[0] - c[0]) + (c[0] - b[0]) * (a[1] - c[1]);
    if (std::abs(d) < 1e-12) return std::nullopt;
    const double w0 = ((b[1] - c[1]) * (x - c[0]) + (c[0] - b[0]) * (y - c[1])) / d;
    const double w1 = ((c[1] - a[1]) * (x - c[0]) + (a[0] - c[0]) * (y - c[1])) / d;
    const double w2 = 1.0 - w0 - w1;
    if (w0 < 0 || w1 < 0 || w2 < 0) return std::nullopt;
    return FrontCrossing{{w0, w1, w2}, w0 * a[2] + w1 * b[2] + w2 * c[2], d > 0};
}

}  // namespace emoface::expression::testing
