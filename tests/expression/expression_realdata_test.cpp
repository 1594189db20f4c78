// Every frame of every real FAP file (Xface, VREng, Greta, ISIR) through
// face_state and the rig on the default face: feature points move and stay
// finite. Reads ${EMOFACE_REALDATA_DIR}/fap; skips when it is absent.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "emoface/expression/face_state.h"
#include "emoface/fap/fap_io.h"
#include "test_face.h"

namespace emoface::expression {
namespace {

std::vector<std::filesystem::path> real_files() {
    std::vector<std::filesystem::path> out;
    const std::filesystem::path dir = std::filesystem::path(EMOFACE_REALDATA_DIR) / "fap";
    if (!std::filesystem::is_directory(dir)) return out;
    for (const auto& e : std::filesystem::directory_iterator(dir))
        if (e.path().extension() == ".fap") out.push_back(e.path());
    std::sort(out.begin(), out.end());
    return out;
}

TEST(RealFapFiles, EveryFrameMovesFeaturePointsAndStaysFinite) {
    const auto files = real_files();
    if (files.empty())
        GTEST_SKIP() << "no real FAP files in " << EMOFACE_REALDATA_DIR << "/fap (set EMOFACE_REALDATA_DIR)";
    const EmotionProfiles emotions = load_emotion_profiles(testing::data_dir() + "/expression/emotions.json");
    const VisemeProfiles visemes = load_viseme_profiles(testing::data_dir() + "/expression/visemes.json");
    const Face& face = testing::test_face();
    const FaceRig& rig = testing::test_rig();
    int files_with_motion = 0;
    for (const auto& path : files) {
        SCOPED_TRACE(path.filename().string());
        const fap::FapStream stream = fap::resolve_untransmitted(fap::read_fap_file(path.string()));
        double largest = 0.0;
        int moving_frames = 0;
        DeformedFace d;
        for (std::size_t k = 0; k < stream.frames.size(); ++k) {
            const FaceState state = face_state(stream.frames[k], emotions, &visemes);
            rig.deform(state.faps, d);
            double frame_motion = 0.0;
            for (int p = 0; p < fap::kFeaturePointCount; ++p) {
                if (!face.has(p)) continue;
                for (double c : d.feature_points[p]) ASSERT_TRUE(std::isfinite(c)) << "frame " << k << " point " << p;
                frame_motion = std::max(frame_motion, testing::distance(d.feature_points[p], face.position(p)));
            }
            for (const auto& q : d.positions)
                ASSERT_TRUE(std::isfinite(q[0]) && std::isfinite(q[1]) && std::isfinite(q[2])) << "frame " << k;
            for (double w : state.mix.weights) ASSERT_TRUE(w >= 0.0 && w <= 1.0) << "frame " << k;
            largest = std::max(largest, frame_motion);
            moving_frames += frame_motion > 0.05;
        }
        // A file that asks for any motion moves the face. (Greta's empty
        // animation has no frames left once its empty one is dropped; ISIR's
        // one frame transmits viseme 0, "none".)
        bool asks = false;
        for (const auto& frame : stream.frames) {
            for (int f = 3; f <= fap::kFapCount; ++f) asks |= frame.has(f) && frame.get(f) != 0.0;
            asks |= frame.has(1) && (frame.viseme.select1 != 0 || frame.viseme.select2 != 0);
            asks |= frame.has(2) && ((frame.expression.select1 != 0 && frame.expression.intensity1 > 0) ||
                                     (frame.expression.select2 != 0 && frame.expression.intensity2 > 0));
        }
        if (asks) {
            EXPECT_GT(largest, 0.5);
            EXPECT_GT(moving_frames, 0);
            ++files_with_motion;
        }
    }
    EXPECT_GT(files_with_motion, 5);
}

TEST(RealFapFiles, XfaceJoyMovesLipsBrowsLidsAndHeadFrameByFrame) {
    const std::filesystem::path path = std::filesystem::path(EMOFACE_REALDATA_DIR) / "fap" / "xface_joy.fap";
    if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " is absent (set EMOFACE_REALDATA_DIR)";
    const EmotionProfiles emotions = load_emotion_profiles(testing::data_dir() + "/expression/emotions.json");
    const fap::FapStream stream = fap::resolve_untransmitted(fap::read_fap_file(path.string()));
    const Face& face = testing::test_face();
    double lips = 0, brows = 0, lids = 0, nose = 0, joy = 0;
    for (const auto& frame : stream.frames) {
        const FaceState s = face_state(frame, emotions);
        const auto fps = testing::test_rig().feature_points(s.faps);
        auto moved = [&](const char* id) { return testing::distance(fps[testing::fp(id)], face.position(testing::fp(id))); };
        lips = std::max({lips, moved("8.3"), moved("2.3")});
        brows = std::max(brows, moved("4.3"));
        lids = std::max(lids, moved("3.1"));
        nose = std::max(nose, moved("9.3"));  // the head turns (48-50)
        joy = std::max(joy, s.mix[Emotion::Joy]);
    }
    EXPECT_GT(lips, 1.0);
    EXPECT_GT(brows, 0.5);
    EXPECT_GT(lids, 0.5);
    EXPECT_GT(nose, 0.2);
    // Plain FAP playback still infers the emotion for the wrinkles.
    EXPECT_GT(joy, 0.3);
}

}  // namespace
}  // namespace emoface::expression
