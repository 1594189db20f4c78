// The baked per-vertex ambient occlusion (ambient_occlusion.h) on height
// fields whose answer is known: a flat sheet is open everywhere, a square
// pit closes in on its floor (a round one of half-width w / 2 and depth d
// leaves its floor's centre a cone of half-angle atan(w / 2d): sin^2 of that
// is the open share; the square's corners leave a little more), more the
// deeper it is, and a far-away wall does not count (obscurance).
#include <cmath>
#include <functional>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "emoface/common/error.h"
#include "emoface/render/ambient_occlusion.h"

namespace {

using emoface::render::bake_vertex_occlusion;
using emoface::render::OcclusionSpec;

// A (2 half + 1)^2 grid of 1 mm spacing, z = height(x, y), normals from
// central differences.
struct Sheet {
    std::vector<glm::vec3> positions, normals;
    std::vector<unsigned> triangles;
    int side = 0;
    int at(int x, int y) const { return y * side + x; }
};
Sheet height_field(int half, const std::function<float(float, float)>& height) {
    Sheet s;
    s.side = 2 * half + 1;
    for (int y = -half; y <= half; ++y)
        for (int x = -half; x <= half; ++x) {
            const float fx = float(x), fy = float(y);
            s.positions.push_back({fx, fy, height(fx, fy)});
            const float dx = height(fx + 0.5f, fy) - height(fx - 0.5f, fy);
            const float dy = height(fx, fy + 0.5f) - height(fx, fy - 0.5f);
            s.normals.push_back(glm::normalize(glm::vec3(-dx, -dy, 1.0f)));
        }
    for (int y = 0; y + 1 < s.side; ++y)
        for (int x = 0; x + 1 < s.side; ++x) {
            const unsigned a = unsigned(s.at(x, y)), b = unsigned(s.at(x + 1, y)),
                           c = unsigned(s.at(x + 1, y + 1)), d = unsigned(s.at(x, y + 1));
            s.triangles.insert(s.triangles.end(), {a, b, c, a, c, d});
        }
    return s;
}
// A square pit `width` wide and `depth` deep at the origin, walls 1 mm wide.
std::function<float(float, float)> pit(float width, float depth) {
    return [=](float x, float y) {
        const float edge = std::max(std::abs(x), std::abs(y)) - 0.5f * width;
        return -depth * std::clamp(0.5f - edge, 0.0f, 1.0f);
    };
}

TEST(AmbientOcclusion, FlatSheetIsOpenEverywhere) {
    const Sheet s = height_field(20, [](float, float) { return 0.0f; });
    const std::vector<float> ao = bake_vertex_occlusion(s.positions, s.normals, s.triangles);
    ASSERT_EQ(ao.size(), s.positions.size());
    for (float a : ao) EXPECT_FLOAT_EQ(a, 1.0f);
}

TEST(AmbientOcclusion, PitDarkensItsFloorAndLeavesTheSheetAroundIt) {
    const Sheet shallow = height_field(25, pit(10.0f, 3.0f)), deep = height_field(25, pit(10.0f, 10.0f));
    OcclusionSpec spec;
    spec.texel_mm = 0.5f;
    const std::vector<float> a = bake_vertex_occlusion(shallow.positions, shallow.normals, shallow.triangles, spec);
    const std::vector<float> b = bake_vertex_occlusion(deep.positions, deep.normals, deep.triangles, spec);
    const int centre = deep.at(25, 25), corner = deep.at(0, 0);
    // The deep pit's floor: a round pit would leave sin^2(atan(5 / 10)) = 0.2 open.
    EXPECT_GT(b[std::size_t(centre)], 0.15f);
    EXPECT_LT(b[std::size_t(centre)], 0.35f);
    // A shallow one (round: sin^2(atan(5 / 3)) = 0.74) closes in less.
    EXPECT_GT(a[std::size_t(centre)], 0.7f);
    EXPECT_LT(a[std::size_t(centre)], 0.92f);
    EXPECT_FLOAT_EQ(b[std::size_t(corner)], 1.0f);
    // The floor's corner, walls on two sides, is darker than its centre.
    EXPECT_LT(b[std::size_t(deep.at(21, 21))], b[std::size_t(centre)]);
}

TEST(AmbientOcclusion, FarWallsDoNotCount) {
    const Sheet s = height_field(25, pit(40.0f, 10.0f));
    OcclusionSpec spec;
    spec.near_mm = 2.0f;
    spec.far_mm = 4.0f;
    const std::vector<float> ao = bake_vertex_occlusion(s.positions, s.normals, s.triangles, spec);
    // Walls 20 mm away from the floor's centre are past far_mm.
    EXPECT_FLOAT_EQ(ao[std::size_t(s.at(25, 25))], 1.0f);
}

TEST(AmbientOcclusion, SameResultEachCall) {
    const Sheet s = height_field(12, pit(8.0f, 6.0f));
    EXPECT_EQ(bake_vertex_occlusion(s.positions, s.normals, s.triangles),
              bake_vertex_occlusion(s.positions, s.normals, s.triangles));
}

// A light's cone (OcclusionSpec::cone_axis): a wall 10 mm high along x = 5
// shades the floor from a light beyond it at 45 degrees out to 10 mm from
// its foot, and not at all from a light behind the floor.
TEST(AmbientOcclusion, AWallCastsTheShadowOfALightBeyondItOnly) {
    const Sheet s = height_field(25, [](float x, float) { return x > 5.0f ? 10.0f : 0.0f; });
    auto visible = [&](glm::vec3 toward) {
        OcclusionSpec spec;
        spec.texel_mm = 0.5f;
        spec.cone_axis = glm::normalize(toward);
        spec.cone_half_angle_deg = 5.0f;
        spec.directions = 16;
        return bake_vertex_occlusion(s.positions, s.normals, s.triangles, spec);
    };
    const std::vector<float> beyond = visible({1, 0, 1}), behind = visible({-1, 0, 1});
    const std::size_t foot = std::size_t(s.at(25 + 0, 25)), far = std::size_t(s.at(25 - 15, 25));
    EXPECT_LT(beyond[foot], 0.1f);
    EXPECT_GT(beyond[far], 0.9f);
    EXPECT_GT(behind[foot], 0.9f);
    // The wall's top sees both.
    const std::size_t top = std::size_t(s.at(25 + 15, 25));
    EXPECT_GT(beyond[top], 0.9f);
    EXPECT_GT(behind[top], 0.9f);
}

TEST(AmbientOcclusion, BadInputIsAnError) {
    const Sheet s = height_field(2, [](float, float) { return 0.0f; });
    std::vector<unsigned> bad = s.triangles;
    bad.back() = unsigned(s.positions.size());
    EXPECT_THROW(bake_vertex_occlusion(s.positions, s.normals, bad), emoface::Error);
    EXPECT_THROW(bake_vertex_occlusion(s.positions, {}, s.triangles), emoface::Error);
    OcclusionSpec wide;
    wide.cone_axis = {0, 0, 1};
    wide.cone_half_angle_deg = 95.0f;
    EXPECT_THROW(bake_vertex_occlusion(s.positions, s.normals, s.triangles, wide), emoface::Error);
}

}  // namespace
