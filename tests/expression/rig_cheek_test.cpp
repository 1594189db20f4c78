// The apple of the cheek (issue 11: "the smile moves only the mouth; the
// cheeks don't lift"): a smile's cheek comes forward and up below the eye,
// lateral to the nasolabial fold, which deepens against the upper lip; AUs
// that do not lift the cheek or the mouth corners leave it.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <string>
#include <vector>

#include "emoface/common/constants.h"
#include "emoface/expression/action_units.h"
#include "emoface/expression/profiles.h"
#include "test_face.h"

namespace emoface::expression {
namespace {

using testing::fp;
using testing::test_face;
using testing::test_rig;
using testing::to_vec;

const EmotionProfiles& profiles() {
    static const EmotionProfiles p = load_emotion_profiles(std::string(EMOFACE_DATA_DIR) + "/expression/emotions.json");
    return p;
}

// The FAPs of the AUs `numbers` at full intensity, summed (AU6 + AU12: the smile without an emotion's other AUs).
FapValues au(std::initializer_list<int> numbers) {
    FapValues sum{};
    for (const int n : numbers) {
        const FapValues& faps = profiles().action_units.find(n)->faps;
        for (std::size_t i = 0; i < sum.size(); ++i) sum[i] += faps[i];
    }
    return sum;
}

struct CheekReading {
    double forward;  // the left cheek's largest forward (z) motion (mm)
    double up;       // its largest upward motion (mm)
    double fold;     // forward - the largest forward motion of the upper lip's skin beside the nose (mm)
};

CheekReading read_cheek(const FapValues& faps) {
    const Face& face = test_face();
    const DeformedFace out = test_rig().deform(faps);
    const Vec3d wing = face.position(fp("9.1")), corner = face.position(fp("8.3"));
    const Vec3d lid = face.position(fp("3.3")), cheek = face.position(fp("5.3"));
    const Vec3d base = face.position(fp("9.15")), lip = face.position(fp("8.1"));
    CheekReading r{0.0, 0.0, 0.0};
    double lip_forward = 0.0;
    for (int v = 0; v < face.vertex_count(); ++v) {
        if (face.parts[v] != VertexPart::Skin) continue;
        const auto p = face.mesh.point(TriMesh::VertexHandle(v));
        const auto q = out.positions[v];
        if (p[2] < cheek[2] - 10.0) continue;  // the front of the face
        // The cheek: lateral to the nose wing, from the mouth corner's
        // height to 12 mm below the lower lid (above, its bulge).
        if (p[0] > wing[0] + 4.0 && p[0] < cheek[0] + 5.0 && p[1] > corner[1] && p[1] < lid[1] - 12.0) {
            r.forward = std::max(r.forward, double(q[2] - p[2]));
            r.up = std::max(r.up, double(q[1] - p[1]));
        }
        // The upper lip's skin between the philtrum and the fold.
        if (p[0] > 0.4 * wing[0] && p[0] < wing[0] && p[1] > lip[1] + 3.0 && p[1] < base[1] - 3.0)
            lip_forward = std::max(lip_forward, double(q[2] - p[2]));
    }
    r.fold = r.forward - lip_forward;
    return r;
}

TEST(RigCheek, ASmileBringsTheCheekForwardAndUpBesideADeeperFold) {
    struct Case {
        std::string what;
        FapValues faps;
        double forward_min, forward_max, fold_min;
    };
    const Case cases[] = {
        // The Duchenne smile: the cheek 3-6 mm forward, the fold 2 mm deeper.
        {"joy", profiles()[Emotion::Joy], 3.0, 6.5, 2.0},
        {"AU6 cheek raiser", au({6}), 2.0, 5.0, 1.5},
        {"AU12 lip corner puller", au({12}), 1.0, 4.0, 0.5},
        // Disgust's nose wrinkler and the upper lip raiser lift it a little
        // (the infraorbital triangle goes up with the lip).
        {"disgust", profiles()[Emotion::Disgust], 0.7, 2.5, 0.5},
        {"AU9 nose wrinkler", au({9}), 0.7, 2.5, 0.5},
        {"AU10 upper lip raiser", au({10}), 0.5, 2.0, 0.3},
        // Nothing lifts the cheek or the corners: it stays.
        {"AU15 lip corner depressor", au({15}), -0.3, 0.3, -1.0},
        {"AU20 lip stretcher", au({20}), -0.3, 0.3, -1.0},
        {"AU4 brow lowerer", au({4}), -0.3, 0.3, -1.0},
        {"AU7 lid tightener", au({7}), -0.3, 0.3, -1.0},
        // Nor do the emotions without AU6, AU9, AU10 or AU12.
        {"sadness", profiles()[Emotion::Sadness], -0.3, 0.3, -1.0},
        {"fear", profiles()[Emotion::Fear], -0.3, 0.3, -1.0},
        {"anger", profiles()[Emotion::Anger], -0.3, 0.3, -1.0},
    };
    for (const Case& c : cases) {
        const CheekReading r = read_cheek(c.faps);
        std::printf("%-28s cheek %+.2f mm forward, %+.2f mm up; fold %+.2f mm deeper\n", c.what.c_str(), r.forward, r.up,
                    r.fold);
        SCOPED_TRACE(c.what);
        EXPECT_GE(r.forward, c.forward_min);
        EXPECT_LE(r.forward, c.forward_max);
        EXPECT_GE(r.fold, c.fold_min);
    }
}

// The smiling cheek is a rounded mound: no line runs from below the eye
// down the cheek (issue 11: joy showed a sharp ridge from the outer eye
// corner towards the mouth corner, along the grid's vertical edge line
// through the cheek point, where distances along edges alone bent the cheek
// kernel). Measured as the largest growth over neutral of the dihedral
// angle between neighbouring skin triangles in a band down the cheekbone:
// within 10 mm of the cheek point's x, from 10 mm below the lower lid's
// point (above: the lid's bulge) to 20 mm above the mouth corner (below:
// the corner's own crowding, the modiolus).
// With `apple` > 0 the region is instead the skin within `apple` mm of the
// apple of the cheek's centre (rig.cpp, kCentreOnCheekbone: 0.75 of the way
// from the nose wing to the cheekbone point).
double largest_cheek_crease(const FapValues& faps, bool left, Vec3d* where, double apple = 0.0) {
    const Face& face = test_face();
    const TriMesh& mesh = face.mesh;
    const Vec3d cheek = face.position(fp(left ? "5.3" : "5.4")), corner = face.position(fp(left ? "8.3" : "8.4"));
    const Vec3d lid = face.position(fp(left ? "3.3" : "3.4"));
    const DeformedFace out = test_rig().deform(faps);
    auto normal = [&](TriMesh::FaceHandle f, bool deformed) {
        std::array<Vec3d, 3> p{};
        int i = 0;
        for (auto v : mesh.fv_range(f)) p[i++] = to_vec(deformed ? out.positions[v.idx()] : mesh.point(v));
        const Vec3d a{p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
        const Vec3d b{p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
        Vec3d n{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
        const double l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (double& c : n) c /= l > 0 ? l : 1.0;
        return n;
    };
    auto angle = [&](TriMesh::FaceHandle f, TriMesh::FaceHandle g, bool deformed) {
        const Vec3d a = normal(f, deformed), b = normal(g, deformed);
        return std::acos(std::clamp(a[0] * b[0] + a[1] * b[1] + a[2] * b[2], -1.0, 1.0)) * 180.0 / kPi;
    };
    double worst = 0.0;
    for (auto e : mesh.edges()) {
        if (mesh.is_boundary(e)) continue;
        const auto h = mesh.halfedge_handle(e, 0);
        const int a = mesh.from_vertex_handle(h).idx(), b = mesh.to_vertex_handle(h).idx();
        if (face.parts[a] != VertexPart::Skin || face.parts[b] != VertexPart::Skin) continue;
        const Vec3d pa = to_vec(mesh.point(TriMesh::VertexHandle(a))), pb = to_vec(mesh.point(TriMesh::VertexHandle(b)));
        const Vec3d mid{0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1]), 0.5 * (pa[2] + pb[2])};
        if (apple > 0) {
            const Vec3d wing = face.position(fp(left ? "9.1" : "9.2"));
            constexpr double k = 0.75;
            const Vec3d centre{k * cheek[0] + (1 - k) * wing[0], k * cheek[1] + (1 - k) * wing[1], k * cheek[2] + (1 - k) * wing[2]};
            if (std::hypot(mid[0] - centre[0], mid[1] - centre[1]) > apple || mid[2] < cheek[2] - 15.0) continue;
        } else if (std::abs(mid[0] - cheek[0]) > 10.0 || mid[1] > lid[1] - 10.0 || mid[1] < corner[1] + 20.0 ||
                   mid[2] < cheek[2] - 15.0) {
            continue;
        }
        const auto f = mesh.face_handle(h), g = mesh.face_handle(mesh.opposite_halfedge_handle(h));
        const double growth = angle(f, g, true) - angle(f, g, false);
        if (growth > worst) worst = growth, *where = mid;
    }
    return worst;
}

TEST(RigCheek, TheSmilingCheekHasNoRidgeDownIt) {
    struct Case {
        std::string what;
        FapValues faps;
    };
    const Case cases[] = {
        {"joy", profiles()[Emotion::Joy]},
        {"AU6 cheek raiser", au({6})},
        {"AU12 lip corner puller", au({12})},
        {"AU6+AU12", au({6, 12})},
        {"disgust", profiles()[Emotion::Disgust]},
        {"AU9", au({9})},
        {"AU10", au({10})},
    };
    // Between triangles of about 2.5 mm (the half-resolution test face) the
    // mound bends each edge by up to about 7 degrees; the ridge along the
    // edge line grew it by 10-14 (joy, AU6, AU6+AU12).
    constexpr double kBound = 9.0;
    for (const Case& c : cases)
        for (const bool left : {true, false}) {
            Vec3d at{};
            const double g = largest_cheek_crease(c.faps, left, &at);
            std::printf("%-24s %s cheek: largest crease growth %5.1f deg at (%.1f, %.1f, %.1f)\n", c.what.c_str(),
                        left ? "left " : "right", g, at[0], at[1], at[2]);
            EXPECT_LE(g, kBound) << c.what << (left ? ", left" : ", right") << " cheek at (" << at[0] << ", " << at[1]
                                 << ", " << at[2] << ")";
        }
}

// The smiling cheek rises as one round mass: its top bends gently (blind
// review, session 9: joy's apple came forward as a pointed crest, its steep
// outer flank a dark streak from below the outer eye corner to the nose wing
// at 512 px). Measured as the largest crease growth within 10 mm of the
// apple's centre: 14.3 deg in joy and 16.0 in AU6+AU12 with a Wendland bell
// over 0.45 ES0; 5.3 and 6.4 with the round bell over 0.55 (rig.cpp,
// kMassRadius); 5.5 and 6.7 centred under the eye over 0.65 (round 14).
TEST(RigCheek, TheSmilingCheekRisesAsOneRoundMass) {
    const std::pair<std::string, FapValues> cases[] = {
        {"joy", profiles()[Emotion::Joy]}, {"AU6+AU12", au({6, 12})}, {"AU6 cheek raiser", au({6})}, {"AU12", au({12})}};
    for (const auto& [what, faps] : cases)
        for (const bool left : {true, false}) {
            Vec3d at{};
            const double g = largest_cheek_crease(faps, left, &at, 10.0);
            std::printf("%-18s %s apple: largest crease growth %4.1f deg at (%.1f, %.1f, %.1f)\n", what.c_str(),
                        left ? "left " : "right", g, at[0], at[1], at[2]);
            EXPECT_LE(g, 7.5) << what << (left ? ", left" : ", right") << " apple at (" << at[0] << ", " << at[1] << ", "
                              << at[2] << ")";
        }
}

// The front-most depth (z) of the skin at (x, y), or NaN off the skin.
double skin_depth_at(const Face& face, const std::vector<Vec3d>& p, double x, double y) {
    static const std::vector<std::array<int, 3>> skin_triangles = [&] {
        std::vector<std::array<int, 3>> out;
        for (auto f : face.mesh.faces()) {
            std::array<int, 3> t{};
            int i = 0;
            bool skin = true;
            for (auto v : face.mesh.fv_range(f)) {
                t[i++] = v.idx();
                skin &= face.parts[v.idx()] == VertexPart::Skin;
            }
            if (skin) out.push_back(t);
        }
        return out;
    }();
    double best = std::nan("");
    for (const auto& t : skin_triangles) {
        const Vec3d &a = p[t[0]], &b = p[t[1]], &c = p[t[2]];
        const double d = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
        if (d <= 0) continue;  // facing away from the front
        const double l1 = ((b[0] - x) * (c[1] - y) - (c[0] - x) * (b[1] - y)) / d;
        const double l2 = ((c[0] - x) * (a[1] - y) - (a[0] - x) * (c[1] - y)) / d;
        const double l3 = 1.0 - l1 - l2;
        if (l1 < 0 || l2 < 0 || l3 < 0) continue;
        const double z = l1 * a[2] + l2 * b[2] + l3 * c[2];
        if (std::isnan(best) || z > best) best = z;
    }
    return best;
}

// The deepest valley (mm) in the forward motion along the lines from the
// nose wing to the outer eye corner of one side.
double deepest_valley_nose_to_eye(const FapValues& faps, bool left, Vec3d* where) {
    const Face& face = test_face();
    std::vector<Vec3d> p0(face.vertex_count()), p1(face.vertex_count());
    const DeformedFace out = test_rig().deform(faps);
    for (int v = 0; v < face.vertex_count(); ++v) {
        p0[v] = to_vec(face.mesh.point(TriMesh::VertexHandle(v)));
        p1[v] = to_vec(out.positions[v]);
    }
    const Vec3d wing = face.position(fp(left ? "9.1" : "9.2")), eye = face.position(fp(left ? "3.7" : "3.12"));
    const double below_lid = face.position(fp(left ? "3.3" : "3.4"))[1] - 8.0;
    const double dx = eye[0] - wing[0], dy = eye[1] - wing[1], len = std::hypot(dx, dy);
    // Across the line, towards the ear and the jaw.
    double px = dy / len, py = -dx / len;
    if (px * (left ? 1.0 : -1.0) < 0) px = -px, py = -py;
    double worst = 0.0;
    for (const double off : {0.0, 3.0, 6.0}) {
        constexpr int kSamples = 41;
        std::vector<double> forward(kSamples, std::nan(""));
        std::vector<Vec3d> at(kSamples);
        for (int i = 0; i < kSamples; ++i) {
            const double t = double(i) / (kSamples - 1);
            const double x = wing[0] + t * dx + off * px, y = wing[1] + t * dy + off * py;
            if (y > below_lid || std::hypot(x - wing[0], y - wing[1]) < 8.0) continue;
            const double z0 = skin_depth_at(face, p0, x, y), z1 = skin_depth_at(face, p1, x, y);
            forward[i] = z1 - z0;
            at[i] = {x, y, z1};
        }
        for (int i = 0; i < kSamples; ++i) {
            if (std::isnan(forward[i])) continue;
            double left_high = forward[i], right_high = forward[i];
            for (int k = 0; k < i; ++k)
                if (!std::isnan(forward[k])) left_high = std::max(left_high, forward[k]);
            for (int k = i + 1; k < kSamples; ++k)
                if (!std::isnan(forward[k])) right_high = std::max(right_high, forward[k]);
            const double valley = std::min(left_high, right_high) - forward[i];
            if (valley > worst) worst = valley, *where = at[i];
        }
    }
    return worst;
}

// No gully runs from the nose wing up to the outer eye corner in a smile
// (blind review, round 14: joy's shadow-side cheek showed "a diagonal
// groove from the side of the nose up toward the outer eye, like a crushed
// mesh, not a smile fold"). Along lines from the nose wing (9.1) to the
// outer eye corner (3.7), and beside them 3 and 6 mm lateral, the skin's
// forward motion (the deformed surface's depth against the neutral one's at
// the same place, seen from the front) rises over the apple without a dip:
// no valley between higher ground on both sides. Only below the lower lid's
// bulge and furrow (8 mm below its point) and away from the fold's top (8 mm
// from the nose wing), which are meant. With the apple low beside the nose
// the skin between it and the raised skin below the lower lid's outer half
// stayed behind (rig.cpp, kCentreOnCheekbone); the bounds below hold the
// apple centred on the cheekbone.
TEST(RigCheek, NoGullyRunsFromTheNoseWingToTheOuterEye) {
    struct Case {
        std::string what;
        FapValues faps;
        double bound;  // mm
    };
    const Case cases[] = {
        // The smile: 1.7-1.9 mm (joy) and 2.0-2.2 (AU6+AU12) with the apple
        // centred 0.6 of the way to the cheekbone over 0.55 ES0; 0.6 and 0.8
        // now.
        {"joy", profiles()[Emotion::Joy], 0.8},
        {"AU6+AU12", au({6, 12}), 1.0},
        // The cheek raised alone, without the corners' share of the mass:
        // 2.1-2.3 mm before, 1.3 now.
        {"AU6 cheek raiser", au({6}), 1.5},
        {"AU12", au({12}), 0.3},
        // Disgust's upper lip lifts the mass a little: 0.9 mm before, 0.4 now.
        {"disgust", profiles()[Emotion::Disgust], 0.6},
    };
    for (const Case& c : cases)
        for (const bool left : {true, false}) {
            Vec3d at{};
            const double v = deepest_valley_nose_to_eye(c.faps, left, &at);
            std::printf("%-18s %s nose wing to outer eye: deepest valley %.2f mm at (%.1f, %.1f, %.1f)\n",
                        c.what.c_str(), left ? "left " : "right", v, at[0], at[1], at[2]);
            EXPECT_LE(v, c.bound) << c.what << (left ? ", left" : ", right") << " at (" << at[0] << ", " << at[1]
                                  << ", " << at[2] << ")";
        }
}
}  // namespace
}  // namespace emoface::expression
