// The FAP rig on the default face: every FAP moves its feature point by value
// x FAPU along the FAP table's direction and leaves distant skin alone; the
// jaw opens the lips, the lids close onto each other, the head turns.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "emoface/common/error.h"
#include "emoface/fap/fap_table.h"
#include "emoface/expression/profiles.h"
#include "emoface/fap/feature_points.h"
#include "test_face.h"

namespace emoface::expression {
namespace {

using testing::distance;
using testing::fp;
using testing::test_face;
using testing::test_rig;
using testing::to_vec;

Vec3d sub(const Vec3d& a, const Vec3d& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const Vec3d& a, const std::array<float, 3>& d) { return a[0] * d[0] + a[1] * d[1] + a[2] * d[2]; }
double norm(const Vec3d& a) { return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }

bool is_rotation(int f) { return (f >= 23 && f <= 26) || (f >= 48 && f <= 50); }

// A value that moves about 2-5 mm on the default face.
double test_value(int f) {
    switch (fap::fap_info(f).unit) {
        case fap::FapUnit::IRISD: return 300;
        case fap::FapUnit::ES:
        case fap::FapUnit::MW: return 60;
        case fap::FapUnit::AU: return 5000;  // 0.05 rad
        default: return 150;
    }
}

TEST(Rig, EveryLowLevelFapHasAnEffectOnTheDefaultFace) {
    int with_effect = 0;
    for (int f = 3; f <= fap::kFapCount; ++f) {
        EXPECT_TRUE(test_rig().has_effect(f)) << f << ": " << test_rig().why_no_effect(f);
        with_effect += test_rig().has_effect(f);
    }
    EXPECT_EQ(with_effect, fap::kLowLevelFapCount);
    EXPECT_FALSE(test_rig().has_effect(1));
    EXPECT_FALSE(test_rig().why_no_effect(2).empty());
    EXPECT_THROW(test_rig().has_effect(69), Error);
}

TEST(Rig, NoFapsIsTheNeutralFace) {
    const DeformedFace d = test_rig().deform(FapValues{});
    const Face& f = test_face();
    ASSERT_EQ(static_cast<int>(d.positions.size()), f.vertex_count());
    for (int v = 0; v < f.vertex_count(); ++v) ASSERT_EQ(d.positions[v], f.mesh.point(TriMesh::VertexHandle(v)));
    for (int k = 0; k < fap::kFeaturePointCount; ++k) EXPECT_EQ(d.feature_points[k], f.feature_points[k].position);
}

// Table-driven over every FAP with a feature point: value x FAPU along the
// table's direction, and nothing moves beyond the FAP's reach.
class EachFap : public ::testing::TestWithParam<int> {};

TEST_P(EachFap, MovesItsFeaturePointAlongTheTableDirectionAndNothingFar) {
    const int f = GetParam();
    const Face& face = test_face();
    const auto& info = fap::fap_info(f);
    const int k = fap::feature_point_index(info.feature_point);
    const double value = test_value(f);
    FapValues faps{};
    faps[f - 1] = value;
    const DeformedFace d = test_rig().deform(faps);
    const Vec3d moved = sub(d.feature_points[k], face.position(k));
    const double es0 = face.fapu.es * 1024;

    double expected = value * face.fapu.of(info.unit);
    if (is_rotation(f)) {
        // A small rotation moves the front of the eye or face along the
        // direction by about angle x the lever's depth in front of the
        // centre (for roll: the crown, by angle x its height above it).
        const double angle = value * face.fapu.au;
        const bool roll = f == 50;
        const int point = roll ? fp("11.4") : f >= 48 ? fp("9.3") : k;
        const Vec3d centre = f >= 48 ? face.head_pivot : face.eyeballs[f % 2 == 1 ? 0 : 1].centre;
        const Vec3d pos = face.position(point);
        const Vec3d lever = sub(pos, centre);
        expected = angle * (roll ? lever[1] : lever[2]);
        EXPECT_NEAR(dot(sub(d.feature_points[point], pos), info.direction), expected, 0.03 * expected);
    } else if (f == 3) {
        // open_jaw rotates the jaw: the chin drops by exactly value x MNS
        // and swings back (its lever hangs below the jaw joint).
        EXPECT_NEAR(dot(moved, info.direction), expected, 1e-3);
        EXPECT_LT(moved[2], 0.0);
    } else if (f == 29 || f == 30) {
        // Pupil dilation: the pupil centre stays, the iris ring widens.
        EXPECT_LT(norm(moved), 1e-6);
        const Eyeball& e = face.eyeballs[f == 29 ? 0 : 1];
        int wider = 0;
        for (int v = e.vertices.first; v < e.vertices.end(); ++v) {
            const Vec3d a = sub(to_vec(face.mesh.point(TriMesh::VertexHandle(v))), e.centre);
            const Vec3d b = sub(to_vec(d.positions[v]), e.centre);
            const double pa = std::acos(std::clamp(a[2] / norm(a), -1.0, 1.0));
            const double pb = std::acos(std::clamp(b[2] / norm(b), -1.0, 1.0));
            EXPECT_GE(pb, pa - 1e-5);
            wider += pb > pa + 1e-4;
        }
        EXPECT_GT(wider, 10);
    } else if (f == 47) {
        // Tongue roll curls both borders up.
        EXPECT_GT(moved[1], 0.1);
        EXPECT_GT(d.feature_points[fp("6.4")][1] - face.position(fp("6.4"))[1], 0.1);
    } else {
        const double along = dot(moved, info.direction);
        // The cheek point lies near the top of the apple of the cheek, which
        // holds its rise back by a fifth of its share there (rig.cpp, kMassUp).
        EXPECT_NEAR(along, expected, (f == 41 || f == 42 ? 0.2 : 0.02) * std::abs(expected) + 1e-4);
        Vec3d across = moved;
        for (int c = 0; c < 3; ++c) across[c] -= along * info.direction[c];
        // Lids slide over the eyeball, which moves them in z as well; a
        // stretched mouth corner glides back round the teeth, 0.6 of its
        // outward move into the plane of the skin beside it (rig.cpp,
        // build_corner_glide), and a rising cheek comes forward over the
        // bone with the apple of the cheek (rig.cpp, kMassForward).
        double allowed = 0.05;
        if (f >= 19 && f <= 22) allowed = 0.7;
        if (f == 6 || f == 7 || f == 53 || f == 54) allowed = 0.7;
        if (f == 41 || f == 42) allowed = 0.46;  // at most the apple's whole forward and outward share
        EXPECT_LT(norm(across), allowed * std::abs(expected) + 1e-4);
    }

    // Far from the FAP's region nothing moves.
    // The field interpolates through the still points around a moved one,
    // so a FAP reaches about two kernel radii; beyond, skin moves by at most
    // 2 % of the point's motion (the last of a smooth fade, no plateau edge).
    Vec3d origin = face.position(k);
    double reach = 2.0 * std::max(test_rig().influence_radius(k), 0.35 * es0) + 0.5;
    // A mouth corner's rise bunches the apple of the cheek (rig.cpp, kMassRadius).
    if (f == 12 || f == 13 || f == 59 || f == 60)
        reach = std::max(reach, distance(origin, face.position(fp(f % 2 == 0 ? "5.3" : "5.4"))) + 0.55 * es0 + 0.5);
    bool skip_far = false;
    if (f == 3 || f == 14 || f == 15) {
        skip_far = true;  // checked below: the head above the mouth stays
        for (int v = 0; v < face.vertex_count(); ++v) {
            const auto p = face.mesh.point(TriMesh::VertexHandle(v));
            if (p[1] > face.position(fp("3.5"))[1]) ASSERT_EQ(d.positions[v], p) << "vertex " << v;
        }
    } else if (f >= 23 && f <= 30) {
        skip_far = true;  // eyeball FAPs move only their eyeball
        const Eyeball& e = face.eyeballs[f % 2 == 1 ? 0 : 1];
        for (int v = 0; v < face.vertex_count(); ++v)
            if (!e.vertices.contains(v)) ASSERT_EQ(d.positions[v], face.mesh.point(TriMesh::VertexHandle(v))) << "vertex " << v;
    } else if (f >= 48) {
        skip_far = true;  // the head turns; the neck's cut stays
        int still = 0;
        for (int v = 0; v < face.vertex_count(); ++v)
            if (face.mesh.point(TriMesh::VertexHandle(v))[1] < face.head_pivot[1] - es0) {
                ASSERT_EQ(d.positions[v], face.mesh.point(TriMesh::VertexHandle(v)));
                ++still;
            }
        EXPECT_GT(still, 50);
    }
    if (!skip_far) {
        int far = 0;
        // Tongue roll moves both tongue borders.
        const Vec3d other = f == 47 ? face.position(fp("6.4")) : origin;
        for (int v = 0; v < face.vertex_count(); ++v) {
            const Vec3d p = to_vec(face.mesh.point(TriMesh::VertexHandle(v)));
            if (distance(p, origin) <= reach || distance(p, other) <= reach) continue;
            ++far;
            ASSERT_LT(distance(to_vec(d.positions[v]), p), 0.02 * std::abs(expected) + 1e-4)
                << "vertex " << v << " at distance " << distance(p, origin);
        }
        EXPECT_GT(far, face.vertex_count() / 3);  // a brow's sheet spans the forehead and the temples
    }
}

std::vector<int> faps_with_points() {
    std::vector<int> out;
    for (int f = 3; f <= fap::kFapCount; ++f) out.push_back(f);
    return out;
}
INSTANTIATE_TEST_SUITE_P(DefaultFace, EachFap, ::testing::ValuesIn(faps_with_points()),
                         [](const ::testing::TestParamInfo<int>& i) {
                             return std::to_string(i.param) + "_" + std::string(fap::fap_info(i.param).name);
                         });

TEST(Rig, OpenJaw512OpensAGapBetweenTheLips) {
    const Face& face = test_face();
    FapValues faps{};
    faps[3 - 1] = 512;
    const DeformedFace d = test_rig().deform(faps);
    const double gap = d.feature_points[fp("2.2")][1] - d.feature_points[fp("2.3")][1];
    // The lower lip rides on the jaw: at least 60 % of the chin's drop.
    EXPECT_GT(gap, 0.6 * 512 * face.fapu.mns);
    // The upper lip stays; every lower-lip slit vertex is below its upper twin.
    EXPECT_LT(distance(d.feature_points[fp("2.2")], face.position(fp("2.2"))), 1e-4);
    EXPECT_LT(d.feature_points[fp("2.8")][1], d.feature_points[fp("2.6")][1] - 2.0);
    EXPECT_LT(d.feature_points[fp("2.9")][1], d.feature_points[fp("2.7")][1] - 2.0);
    // Teeth part: the lower incisors follow the jaw.
    EXPECT_LT(d.feature_points[fp("9.11")][1], face.position(fp("9.11"))[1] - 3.0);
    EXPECT_LT(distance(d.feature_points[fp("9.10")], face.position(fp("9.10"))), 1e-4);
}

// A dropped jaw opens the lips as an oval: widest mid-mouth, narrowing
// towards the corners, which stay closed (a slot as wide as the mouth read
// as a letterbox, not a jaw drop).
TEST(Rig, OpenJawOpensAnOvalNarrowingIntoTheCorners) {
    FapValues faps{};
    faps[3 - 1] = 700;
    const DeformedFace d = test_rig().deform(faps);
    auto gap = [&](const char* upper, const char* lower) {
        return d.feature_points[fp(upper)][1] - d.feature_points[fp(lower)][1];
    };
    const double mid = gap("2.2", "2.3");
    const double half_left = gap("2.6", "2.8"), half_right = gap("2.7", "2.9");
    // Measured: 17.7 mm mid-mouth, 8.7 mm halfway to the corners.
    EXPECT_GT(half_left, 2.0);
    EXPECT_GT(half_right, 2.0);
    EXPECT_LT(half_left, 0.85 * mid);
    EXPECT_LT(half_right, 0.85 * mid);
}

// What a ray along -z from (x, y, in front of the face) meets first.
struct Hit {
    VertexPart part;  // its triangle's first vertex's
    bool back;        // the triangle faces away from the ray's origin: the surface's inside
};
using Triangles = std::vector<std::array<int, 3>>;
std::optional<Hit> first_hit(const Face& face, const DeformedFace& d, const Triangles& triangles, double x, double y) {
    std::optional<Hit> hit;
    double nearest = -1e9;
    for (const auto& v : triangles) {
        const auto crossing = testing::front_crossing(d.positions[v[0]], d.positions[v[1]], d.positions[v[2]], x, y);
        if (crossing && crossing->z > nearest) nearest = crossing->z, hit = Hit{face.parts[v[0]], !crossing->facing};
    }
    return hit;
}

// Mouths in the poses that open or stretch them most: the six emotions,
// the jaw dropped, and the widest open mouth the AUs make (lips stretched,
// jaw stretched open); with the triangles that lie round the mouth.
struct OpenMouthCase {
    std::string what;
    DeformedFace d;
};
struct OpenMouthPoses {
    std::vector<OpenMouthCase> cases;
    Triangles triangles;
};
const OpenMouthPoses& open_mouths() {
    static const OpenMouthPoses poses = [] {
        const EmotionProfiles profiles =
            load_emotion_profiles(std::string(EMOFACE_DATA_DIR) + "/expression/emotions.json");
        OpenMouthPoses m;
        for (const Emotion e : kEmotions)
            m.cases.push_back({emotion_name(e), test_rig().deform(profiles.profiles[emotion_index(e)])});
        FapValues jaw{};
        jaw[3 - 1] = 700;
        m.cases.push_back({"open jaw 700", test_rig().deform(jaw)});
        FapValues scream{};
        for (const int au : {20, 27})
            for (std::size_t i = 0; i < scream.size(); ++i) scream[i] += profiles.action_units.find(au)->faps[i];
        m.cases.push_back({"AU20 + AU27", test_rig().deform(scream)});
        const Face& face = test_face();
        const Vec3d stomion = face.position(fp("2.2"));
        for (const auto fh : face.mesh.faces()) {
            std::array<int, 3> v{};
            int k = 0;
            bool near = false;
            for (const auto vh : face.mesh.fv_range(fh)) {
                v[k++] = vh.idx();
                const auto p = face.mesh.point(vh);
                near |= std::abs(p[0] - stomion[0]) < 60 && std::abs(p[1] - stomion[1]) < 45;
            }
            if (near) m.triangles.push_back(v);
        }
        return m;
    }();
    return poses;
}

// Looking into an open mouth one sees its inside up to the corners: the
// cavity, teeth or tongue, never the skin's inside past the cavity's rim
// (with the cavity 25 mm wide beside 26 mm lip corners, surprise and fear
// showed a skin-lit triangle in the face's left corner, round 18).
TEST(OpenMouths, ShowTheirInsideIntoTheCorners) {
    const Face& face = test_face();
    int looked = 0;
    for (const OpenMouthCase& c : open_mouths().cases) {
        const DeformedFace& d = c.d;
        for (const auto& [corner, upper, lower] : {std::array<const char*, 3>{"2.4", "2.6", "2.8"},
                                                   std::array<const char*, 3>{"2.5", "2.7", "2.9"}}) {
            const Vec3d k = d.feature_points[fp(corner)], u = d.feature_points[fp(upper)],
                        l = d.feature_points[fp(lower)];
            if (u[1] - l[1] < 2.0) continue;  // closed there
            for (const double t : {0.05, 0.1, 0.2, 0.35}) {
                // On the line from the corner to the middle of the half-way gap.
                const double x = k[0] + t * (0.5 * (u[0] + l[0]) - k[0]), y = k[1] + t * (0.5 * (u[1] + l[1]) - k[1]);
                const auto hit = first_hit(face, d, open_mouths().triangles, x, y);
                ASSERT_TRUE(hit.has_value()) << c.what << ": nothing behind the mouth at " << corner;
                EXPECT_FALSE(hit->part == VertexPart::Skin && hit->back)
                    << c.what << ": the skin's inside shows " << t << " of the way in from corner " << corner;
                ++looked;
            }
        }
    }
    std::printf("looked into %d points of open mouths\n", looked);
    EXPECT_GE(looked, 24);
}

// The mouth's inside shows only between the lips: nowhere round the mouth
// does the cavity (or a tooth) stand in front of the skin (a cavity 34 mm
// wide about z 70 came through the cheek beside anger's tightened corners
// as a dark red line).
TEST(OpenMouths, KeepTheirInsideBehindTheSkin) {
    const Face& face = test_face();
    int inside_seen = 0;
    for (const OpenMouthCase& c : open_mouths().cases) {
        const DeformedFace& d = c.d;
        // The lips' opening: the box round the inner contour.
        double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
        for (const char* id : {"2.2", "2.3", "2.4", "2.5", "2.6", "2.7", "2.8", "2.9"}) {
            const Vec3d p = d.feature_points[fp(id)];
            x0 = std::min(x0, p[0]), x1 = std::max(x1, p[0]), y0 = std::min(y0, p[1]), y1 = std::max(y1, p[1]);
        }
        const Vec3d stomion = d.feature_points[fp("2.2")];
        for (double y = stomion[1] - 30; y <= stomion[1] + 20; y += 1.0)
            for (double x = stomion[0] - 50; x <= stomion[0] + 50; x += 1.0) {
                const auto hit = first_hit(face, d, open_mouths().triangles, x, y);
                if (!hit || hit->part == VertexPart::Skin) continue;
                ++inside_seen;
                EXPECT_TRUE(x > x0 - 0.5 && x < x1 + 0.5 && y > y0 - 0.5 && y < y1 + 0.5)
                    << c.what << ": the mouth's inside (part " << part_name(hit->part) << ") shows at (" << x << ", "
                    << y << "), outside the lips' opening x " << x0 << ".." << x1 << ", y " << y0 << ".." << y1;
            }
    }
    std::printf("the mouth's inside seen at %d points\n", inside_seen);
    EXPECT_GT(inside_seen, 100);
}

TEST(Rig, ClosingEyelids1024PutsUpperOnLowerAlongTheWholeMargin) {
    const Face& face = test_face();
    FapValues faps{};
    faps[19 - 1] = faps[20 - 1] = 1024;
    const DeformedFace d = test_rig().deform(faps);
    for (int side = 0; side < 2; ++side) {
        SCOPED_TRACE(side);
        const int up = fp(side == 0 ? "3.1" : "3.2"), lo = fp(side == 0 ? "3.3" : "3.4");
        EXPECT_NEAR(d.feature_points[up][1], d.feature_points[lo][1], 1e-3);
        EXPECT_LT(distance(d.feature_points[up], d.feature_points[lo]), 0.3);
        const Eyeball& e = face.eyeballs[side];
        for (std::size_t i = 0; i < e.upper_margin.size(); ++i) {
            const Vec3d a = to_vec(d.positions[e.upper_margin[i]]), b = to_vec(d.positions[e.lower_margin[i]]);
            EXPECT_LT(distance(a, b), 0.5) << "margin vertex " << i;
            // The lid slid over the eyeball, not through it.
            EXPECT_GE(distance(a, e.centre), e.radius);
        }
    }
}

TEST(Rig, EachLipsFapsLeaveTheOtherLipStill) {
    const Face& face = test_face();
    struct Case {
        std::vector<int> faps;                 // each pushed to 300 alone
        std::vector<const char*> still_points;  // the other lip's points
    };
    const Case cases[] = {
        {{4, 8, 9, 17, 51, 55, 56}, {"2.3", "2.8", "2.9", "8.2", "8.7", "8.8"}},   // upper lip: lower stays
        {{5, 10, 11, 16, 52, 57, 58}, {"2.2", "2.6", "2.7", "8.1", "8.5", "8.6"}},  // lower lip: upper stays
    };
    for (const Case& c : cases)
        for (int f : c.faps) {
            FapValues faps{};
            faps[f - 1] = 300;
            const DeformedFace d = test_rig().deform(faps);
            for (const char* id : c.still_points)
                EXPECT_LT(distance(d.feature_points[fp(id)], face.position(fp(id))), 1e-5)
                    << "FAP " << f << " moved " << id;
        }
}

TEST(Rig, HeadPitchTiltsTheWholeHeadForward) {
    const Face& face = test_face();
    FapValues faps{};
    faps[48 - 1] = 10000;  // 0.1 rad, "down"
    const DeformedFace d = test_rig().deform(faps);
    const Vec3d nose = sub(d.feature_points[fp("9.3")], face.position(fp("9.3")));
    const Vec3d crown = sub(d.feature_points[fp("11.4")], face.position(fp("11.4")));
    EXPECT_LT(nose[1], -5.0);  // the face goes down
    EXPECT_GT(crown[2], 5.0);  // the top of the head goes forward
    // Distances within the head are kept (a rotation).
    EXPECT_NEAR(distance(d.feature_points[fp("3.5")], d.feature_points[fp("3.6")]),
                distance(face.position(fp("3.5")), face.position(fp("3.6"))), 1e-3);
    // 7.1 is the pivot.
    EXPECT_LT(distance(d.feature_points[fp("7.1")], face.position(fp("7.1"))), 1e-9);
}

TEST(Rig, WriteToUpdatesPointsAndNormals) {
    const Face& face = test_face();
    FapValues faps{};
    faps[49 - 1] = 20000;  // yaw 0.2 rad to the left
    const DeformedFace d = test_rig().deform(faps);
    TriMesh mesh = face.mesh;
    FaceRig::write_to(d, mesh);
    const TriMesh::VertexHandle tip(face.feature_points[fp("9.3")].vertex);
    EXPECT_EQ(mesh.point(tip), d.positions[tip.idx()]);
    EXPECT_GT(mesh.normal(tip)[0], face.mesh.normal(tip)[0] + 0.1f);
    DeformedFace wrong;
    EXPECT_THROW(FaceRig::write_to(wrong, mesh), Error);
}

TEST(Rig, FeaturePointsMatchTheFullDeformation) {
    FapValues faps{};
    faps[3 - 1] = 200;
    faps[33 - 1] = 150;
    faps[59 - 1] = 100;
    const auto fps = test_rig().feature_points(faps);
    const DeformedFace d = test_rig().deform(faps);
    for (int k = 0; k < fap::kFeaturePointCount; ++k) EXPECT_EQ(fps[k], d.feature_points[k]);
}

}  // namespace
}  // namespace emoface::expression
