// Tangent frames on analytic surfaces: orthonormal, right-handed where the UV
// map is, equal to the analytic dp/du; mirrored UVs flip the handedness.
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "emoface/common/error.h"
#include "emoface/render/tangents.h"

namespace {

using emoface::expression::TriMesh;
using emoface::render::TangentFrames;

constexpr float kPi = 3.14159265358979f;

struct Surface {
    std::string name;
    // p(s, t) and its analytic unit normal and unit dp/du for s, t in [0, 1].
    std::function<glm::vec3(float, float)> point;
    std::function<glm::vec3(float, float)> normal;
    std::function<glm::vec3(float, float)> dpdu;
    // Whether dp/du, dp/dv, n form a right-handed frame for u = s, v = t.
    float handedness;
    // Grid rows/cols and the range of t used (poles of the sphere excluded).
    int cols, rows;
    float t0, t1;
};

// A grid mesh over the parameter rectangle; UV = (s, t) or mirrored (1 - s, t).
struct GridMesh {
    TriMesh mesh;
    std::vector<glm::vec2> uv;
    std::vector<glm::vec2> st;
};

GridMesh make_grid(const Surface& s, bool mirror_u) {
    GridMesh g;
    g.mesh.request_vertex_normals();
    std::vector<TriMesh::VertexHandle> vh;
    for (int j = 0; j <= s.rows; ++j)
        for (int i = 0; i <= s.cols; ++i) {
            const float u = float(i) / s.cols;
            const float t = s.t0 + (s.t1 - s.t0) * float(j) / s.rows;
            const glm::vec3 p = s.point(u, t);
            const glm::vec3 n = s.normal(u, t);
            vh.push_back(g.mesh.add_vertex({p.x, p.y, p.z}));
            g.mesh.set_normal(vh.back(), {n.x, n.y, n.z});
            g.uv.push_back({mirror_u ? 1.0f - u : u, t});
            g.st.push_back({u, t});
        }
    const int w = s.cols + 1;
    for (int j = 0; j < s.rows; ++j)
        for (int i = 0; i < s.cols; ++i) {
            const auto a = vh[j * w + i], b = vh[j * w + i + 1], c = vh[(j + 1) * w + i + 1],
                       d = vh[(j + 1) * w + i];
            g.mesh.add_face(a, b, c);
            g.mesh.add_face(a, c, d);
        }
    return g;
}

std::vector<Surface> surfaces() {
    std::vector<Surface> out;
    out.push_back({"plane",
                   [](float u, float v) { return glm::vec3(2 * u - 1, 3 * v, 0.5f); },
                   [](float, float) { return glm::vec3(0, 0, 1); },
                   [](float, float) { return glm::vec3(1, 0, 0); }, 1.0f, 8, 8, 0.0f, 1.0f});
    // Cylinder around y, u going around (counter-clockwise seen from +y is
    // towards -z ... here x = sin, z = cos so dp/du points along +phi).
    out.push_back({"cylinder",
                   [](float u, float v) {
                       const float a = 2 * kPi * u * 0.75f;
                       return glm::vec3(std::sin(a), 2 * v, std::cos(a));
                   },
                   [](float u, float) {
                       const float a = 2 * kPi * u * 0.75f;
                       return glm::vec3(std::sin(a), 0, std::cos(a));
                   },
                   [](float u, float) {
                       const float a = 2 * kPi * u * 0.75f;
                       return glm::vec3(std::cos(a), 0, -std::sin(a));
                   },
                   1.0f, 48, 6, 0.0f, 1.0f});
    // Sphere with longitude u and latitude v (poles left out).
    out.push_back({"sphere",
                   [](float u, float v) {
                       const float a = 2 * kPi * u * 0.75f, b = kPi * (v - 0.5f);
                       return glm::vec3(std::cos(b) * std::sin(a), std::sin(b),
                                        std::cos(b) * std::cos(a));
                   },
                   [](float u, float v) {
                       const float a = 2 * kPi * u * 0.75f, b = kPi * (v - 0.5f);
                       return glm::vec3(std::cos(b) * std::sin(a), std::sin(b),
                                        std::cos(b) * std::cos(a));
                   },
                   [](float u, float) {
                       const float a = 2 * kPi * u * 0.75f;
                       return glm::vec3(std::cos(a), 0, -std::sin(a));
                   },
                   1.0f, 48, 32, 0.1f, 0.9f});
    return out;
}

class TangentSurfaces : public ::testing::TestWithParam<Surface> {};

TEST_P(TangentSurfaces, OrthonormalRightHandedAndAnalytic) {
    const Surface& s = GetParam();
    GridMesh g = make_grid(s, false);
    TangentFrames frames;
    frames.compute(g.mesh, g.uv);
    ASSERT_EQ(frames.tangents().size(), g.mesh.n_vertices());
    EXPECT_EQ(frames.fallback_count(), 0u);
    float worst = 0.0f;
    for (const auto vh : g.mesh.vertices()) {
        const glm::vec4 t = frames.tangents()[vh.idx()];
        const auto& nn = g.mesh.normal(vh);
        const glm::vec3 n(nn[0], nn[1], nn[2]);
        const glm::vec3 tt(t);
        EXPECT_NEAR(glm::length(tt), 1.0f, 1e-5f) << s.name << " vertex " << vh.idx();
        EXPECT_NEAR(glm::dot(tt, n), 0.0f, 1e-5f) << s.name << " vertex " << vh.idx();
        EXPECT_EQ(t.w, s.handedness) << s.name << " vertex " << vh.idx();
        const glm::vec2 st = g.st[vh.idx()];
        worst = std::max(worst, glm::length(tt - s.dpdu(st.x, st.y)));
    }
    // Finite differences over a 48-segment circle are within ~2 degrees of
    // the analytic tangent; a wrong axis or sign is off by 1.4 or 2.
    EXPECT_LT(worst, 0.05f) << s.name;
}

TEST_P(TangentSurfaces, MirroredUvsFlipHandedness) {
    const Surface& s = GetParam();
    GridMesh g = make_grid(s, true);
    TangentFrames frames;
    frames.compute(g.mesh, g.uv);
    for (const auto vh : g.mesh.vertices()) {
        const glm::vec4 t = frames.tangents()[vh.idx()];
        EXPECT_EQ(t.w, -s.handedness) << s.name << " vertex " << vh.idx();
        const glm::vec2 st = g.st[vh.idx()];
        // u now runs the other way: dp/du is the analytic tangent negated.
        EXPECT_LT(glm::length(glm::vec3(t) + s.dpdu(st.x, st.y)), 0.05f)
            << s.name << " vertex " << vh.idx();
    }
}

INSTANTIATE_TEST_SUITE_P(Analytic, TangentSurfaces, ::testing::ValuesIn(surfaces()),
                         [](const auto& info) { return info.param.name; });

// A plane whose left half has u mirrored (like a face's two halves sharing
// one side of a texture): the seam vertices must not cancel to nothing.
TEST(Tangents, MirrorSeamKeepsAUsableFrame) {
    Surface plane = surfaces()[0];
    GridMesh g = make_grid(plane, false);
    for (std::size_t i = 0; i < g.uv.size(); ++i)
        g.uv[i].x = std::fabs(g.st[i].x - 0.5f);  // u = |s - 1/2|
    TangentFrames frames;
    frames.compute(g.mesh, g.uv);
    for (const auto vh : g.mesh.vertices()) {
        const glm::vec4 t = frames.tangents()[vh.idx()];
        const float s = g.st[vh.idx()].x;
        EXPECT_NEAR(glm::length(glm::vec3(t)), 1.0f, 1e-5f);
        if (s < 0.49f) {
            EXPECT_EQ(t.w, -1.0f) << "vertex " << vh.idx();
            EXPECT_NEAR(t.x, -1.0f, 1e-5f);
        } else if (s > 0.51f) {
            EXPECT_EQ(t.w, 1.0f) << "vertex " << vh.idx();
            EXPECT_NEAR(t.x, 1.0f, 1e-5f);
        } else {
            EXPECT_NEAR(std::fabs(t.x), 1.0f, 1e-5f) << "seam vertex " << vh.idx();
            EXPECT_NEAR(t.x * t.w, 1.0f, 1e-5f) << "seam vertex: bitangent must stay +y";
        }
    }
}

// Degenerate UVs: every face of a region maps to one UV point or a line.
// Those vertices get a fallback perpendicular to the normal; nothing is NaN.
TEST(Tangents, DegenerateUvsGiveAFiniteFallback) {
    Surface plane = surfaces()[0];
    struct Case {
        const char* name;
        std::function<glm::vec2(glm::vec2)> uv;
        bool all_fallback;
    };
    const Case cases[] = {
        {"all UVs one point", [](glm::vec2) { return glm::vec2(0.3f, 0.3f); }, true},
        {"UVs on a line", [](glm::vec2 st) { return glm::vec2(st.x, st.x); }, true},
        {"NaN UVs", [](glm::vec2) { return glm::vec2(std::nanf(""), 0.0f); }, true},
        {"left half collapsed", [](glm::vec2 st) { return st.x < 0.3f ? glm::vec2(0) : st; },
         false},
    };
    for (const Case& c : cases) {
        GridMesh g = make_grid(plane, false);
        for (std::size_t i = 0; i < g.uv.size(); ++i) g.uv[i] = c.uv(g.st[i]);
        TangentFrames frames;
        frames.compute(g.mesh, g.uv);
        if (c.all_fallback) EXPECT_EQ(frames.fallback_count(), g.mesh.n_vertices()) << c.name;
        else {
            EXPECT_GT(frames.fallback_count(), 0u) << c.name;
            EXPECT_LT(frames.fallback_count(), g.mesh.n_vertices()) << c.name;
        }
        for (const auto vh : g.mesh.vertices()) {
            const glm::vec4 t = frames.tangents()[vh.idx()];
            ASSERT_TRUE(std::isfinite(t.x) && std::isfinite(t.y) && std::isfinite(t.z)) << c.name;
            EXPECT_NEAR(glm::length(glm::vec3(t)), 1.0f, 1e-5f) << c.name;
            EXPECT_NEAR(t.z, 0.0f, 1e-5f) << c.name << ": perpendicular to the normal +z";
            EXPECT_TRUE(t.w == 1.0f || t.w == -1.0f) << c.name;
        }
    }
}

// Recomputing for new UVs on the same mesh reuses the buffers and follows
// the new UVs (the per-frame projective wrinkle UVs).
TEST(Tangents, RecomputeFollowsNewUvs) {
    Surface plane = surfaces()[0];
    GridMesh g = make_grid(plane, false);
    TangentFrames frames;
    frames.compute(g.mesh, g.uv);
    const glm::vec4* storage = frames.tangents().data();
    for (auto& uv : g.uv) uv = {uv.y, uv.x};  // swap u and v: tangent along +y, mirrored
    frames.compute(g.mesh, g.uv);
    EXPECT_EQ(frames.tangents().data(), storage);
    for (const glm::vec4& t : frames.tangents()) {
        EXPECT_NEAR(t.y, 1.0f, 1e-5f);
        EXPECT_EQ(t.w, -1.0f);
    }
}

TEST(Tangents, UsesTheMeshTexcoordsWhenNoUvsAreGiven) {
    Surface plane = surfaces()[0];
    GridMesh g = make_grid(plane, true);
    g.mesh.request_vertex_texcoords2D();
    for (const auto vh : g.mesh.vertices())
        g.mesh.set_texcoord2D(vh, {g.uv[vh.idx()].x, g.uv[vh.idx()].y});
    TangentFrames frames;
    frames.compute(g.mesh);
    for (const glm::vec4& t : frames.tangents()) {
        EXPECT_NEAR(t.x, -1.0f, 1e-5f);
        EXPECT_EQ(t.w, -1.0f);
    }
}

TEST(Tangents, BadInputIsAnError) {
    Surface plane = surfaces()[0];
    GridMesh g = make_grid(plane, false);
    TangentFrames frames;
    std::vector<glm::vec2> short_uvs(g.uv.begin(), g.uv.end() - 1);
    try {
        frames.compute(g.mesh, short_uvs);
        FAIL() << "no error for a short UV array";
    } catch (const emoface::Error& e) {
        EXPECT_EQ(std::string(e.what()),
                  "render: TangentFrames::compute(): expected one UV per vertex (81), got 80");
    }
    TriMesh no_normals;
    no_normals.add_vertex({0, 0, 0});
    std::vector<glm::vec2> one(1);
    EXPECT_THROW(frames.compute(no_normals, one), emoface::Error);
    EXPECT_THROW(frames.compute(no_normals), emoface::Error);  // no texcoords either
}

}  // namespace
