#pragma once
// One default face (and rig) per test process: generating it is the slow
// part, and every test only reads it. Half resolution and a small texture
// keep the ASan run short; proportions and feature points do not depend on it.
#include <array>
#include <optional>
#include <string>

#include "emoface/expression/default_face.h"
#include "emoface/expression/rig.h"

namespace emoface::expression::testing {

inline std::string data_dir() { return EMOFACE_DATA_DIR; }
const Face& test_face();
const FaceRig& test_rig();
// Index of feature point `id`.
int fp(const char* id);
// Distance between two points.
double distance(const Vec3d& a, const Vec3d& b);
Vec3d to_vec(const TriMesh::Point& p);
// Where a ray from the front (along -z) through (x, y) crosses triangle
// abc: the barycentric weights, the depth and whether abc faces the front
// (counter-clockwise seen from +z); none where its projection misses.
struct FrontCrossing {
    std::array<double, 3> w;
    double z;
    bool facing;
};
std::optional<FrontCrossing> front_crossing(const TriMesh::Point& a, const TriMesh::Point& b, const TriMesh::Point& c,
                                            double x, double y);

}  // namespace emoface::expression::testing
