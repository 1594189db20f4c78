// The rig's kernel body (rig_kernel.h), run on all cores by FaceRig::deform,
// against the rig as it ran before, stage after stage on one thread
// (FaceRig::deform_reference), on the default face: every low-level FAP
// alone, each action unit at full intensity, all of them at once, values past
// the human ranges (clamped), and a frame where everything moves together.
// Both use doubles where the rig does; they differ only by FMA contraction
// and a float cosine, far below a micrometre.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "emoface/expression/action_units.h"
#include "emoface/fap/fap_table.h"
#include "test_face.h"

namespace emoface::expression {
namespace {

using testing::test_face;
using testing::test_rig;

struct NamedFrame {
    std::string name;
    FapValues faps{};
};

// A value that moves about 2-5 mm on the default face (as rig_test's).
double moderate(int f) {
    switch (fap::fap_info(f).unit) {
        case fap::FapUnit::IRISD: return 300;
        case fap::FapUnit::ES:
        case fap::FapUnit::MW: return 60;
        case fap::FapUnit::AU: return 5000;
        default: return 150;
    }
}

std::vector<NamedFrame> frames() {
    std::vector<NamedFrame> out;
    out.push_back({"neutral", {}});
    NamedFrame all{"every FAP at once"}, past{"every FAP 20x, past its range"};
    for (int f = 3; f <= fap::kFapCount; ++f) {
        NamedFrame one{"FAP " + std::to_string(f)};
        one.faps[f - 1] = moderate(f);
        out.push_back(one);
        NamedFrame neg{"FAP " + std::to_string(f) + " negative"};
        neg.faps[f - 1] = -moderate(f);
        out.push_back(neg);
        all.faps[f - 1] = moderate(f);
        past.faps[f - 1] = (f % 2 ? 20 : -20) * moderate(f);
    }
    out.push_back(all);
    out.push_back(past);
    const ActionUnitTable aus = load_action_units(testing::data_dir() + "/expression/action_units.json");
    NamedFrame every_au{"every AU at full intensity"};
    for (const ActionUnit& au : aus.units) {
        out.push_back({"AU" + std::to_string(au.number), au.faps});
        for (int i = 0; i < fap::kFapCount; ++i) every_au.faps[i] += au.faps[i];
    }
    out.push_back(every_au);
    NamedFrame together{"lids closed, jaw open, eyes turned and dilated, head turned"};
    together.faps[19 - 1] = together.faps[20 - 1] = 1024;
    together.faps[3 - 1] = 512;
    together.faps[23 - 1] = together.faps[24 - 1] = 20000;
    together.faps[29 - 1] = together.faps[30 - 1] = 400;
    together.faps[48 - 1] = 15000;
    together.faps[49 - 1] = -20000;
    together.faps[50 - 1] = 8000;
    together.faps[53 - 1] = together.faps[54 - 1] = 200;
    out.push_back(together);
    return out;
}

TEST(RigKernel, CpuBodyMatchesTheSequentialRig) {
    const FaceRig& rig = test_rig();
    DeformedFace d;
    int checked = 0;
    for (const NamedFrame& frame : frames()) {
        rig.deform(frame.faps, d);
        const DeformedFace ref = rig.deform_reference(frame.faps);
        ASSERT_EQ(d.positions.size(), ref.positions.size());
        double worst = 0;
        int worst_v = -1;
        for (std::size_t v = 0; v < ref.positions.size(); ++v) {
            const auto diff = d.positions[v] - ref.positions[v];
            const double e = std::max({std::fabs(diff[0]), std::fabs(diff[1]), std::fabs(diff[2])});
            if (!(e <= worst)) worst = e, worst_v = int(v);
        }
        // 1e-4 of the face's units (mm): a few float ulps of a 100 mm coordinate.
        EXPECT_LE(worst, 1e-4) << frame.name << ": vertex " << worst_v;
        for (int k = 0; k < fap::kFeaturePointCount; ++k)
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(d.feature_points[k][c], ref.feature_points[k][c], 1e-4) << frame.name << ": point " << k;
        ++checked;
    }
    EXPECT_GT(checked, 150);
}

TEST(RigKernel, MovedFramesMoveTheMesh) {
    // Not a vacuous comparison: the frames above do move the face.
    const FaceRig& rig = test_rig();
    FapValues faps{};
    faps[3 - 1] = 512;
    faps[19 - 1] = 1024;
    faps[49 - 1] = 10000;
    const DeformedFace d = rig.deform(faps);
    double moved = 0;
    for (int v = 0; v < test_face().vertex_count(); ++v) {
        const auto diff = d.positions[v] - test_face().mesh.point(TriMesh::VertexHandle(v));
        moved = std::max(moved, double(diff.norm()));
    }
    EXPECT_GT(moved, 3.0);
}

TEST(RigKernel, FeaturePointsFromTheFrameAreTheMeshs) {
    const FaceRig& rig = test_rig();
    for (const NamedFrame& frame : frames()) {
        const RigFrame f = rig.frame(frame.faps);
        const fap::FeaturePointPositions points = rig.feature_points(f);
        const DeformedFace d = rig.deform(frame.faps);
        for (int k = 0; k < fap::kFeaturePointCount; ++k) EXPECT_EQ(points[k], d.feature_points[k]) << frame.name << ": " << k;
    }
}

}  // namespace
}  // namespace emoface::expression
