// The apple of the cheek (issue 11: "the smile moves only the mouth; the
// cheeks don't lift"): a smile's cheek comes forward and up below the eye,
// lateral to the nasolabial fold, which deepens against the upper lip; AUs
// that do not lift the cheek or the mouth corners leave it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "emoface/expression/action_units.h"
#include "emoface/expression/profiles.h"
#include "test_face.h"

namespace emoface::expression {
namespace {

using testing::fp;
using testing::test_face;
using testing::test_rig;

const EmotionProfiles& profiles() {
    static const EmotionProfiles p = load_emotion_profiles(std::string(EMOFACE_DATA_DIR) + "/expression/emotions.json");
    return p;
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
    const ActionUnitTable& aus = profiles().action_units;
    auto au = [&](int n) { return aus.find(n)->faps; };
    const Case cases[] = {
        // The Duchenne smile: the cheek 3-6 mm forward, the fold 2 mm deeper.
        {"joy", profiles()[Emotion::Joy], 3.0, 6.5, 2.0},
        {"AU6 cheek raiser", au(6), 2.0, 5.0, 1.5},
        {"AU12 lip corner puller", au(12), 1.0, 4.0, 0.5},
        // Nothing lifts the cheek or the corners: it stays.
        {"AU15 lip corner depressor", au(15), -0.3, 0.3, -1.0},
        {"AU20 lip stretcher", au(20), -0.3, 0.3, -1.0},
        {"AU4 brow lowerer", au(4), -0.3, 0.3, -1.0},
        {"AU7 lid tightener", au(7), -0.3, 0.3, -1.0},
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

}  // namespace
}  // namespace emoface::expression
