// What a new user meets first (issue 10, "rough edges"): play makes a
// missing output folder; --frames errors quote the user's text; usage lines
// say `emoface`, not the binary's path; `info` reports what FAP 1 and FAP 2
// drive; inspect prints its stage timings and a title without a doubled
// "mix"; inspect's labels never overlap and stay inside the picture.
#include <algorithm>
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "au_label.h"
#include "label_placement.h"
#include "session.h"
#include "sheet.h"
#include "support/run_emoface.h"
#include "support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using emoface::apps::FeatureLabel;
using emoface::apps::LabelRequest;
using emoface::apps::place_labels;
using emoface::testing::args_with;
using emoface::testing::CommandResult;
using emoface::testing::run_emoface;

const std::string kData = EMOFACE_DATA_DIR;
const std::string kTour = kData + "/fap/tour.fap";  // 50 frames
const std::string kDemoTour = kData + "/fap/demo_tour.fap";
// Small and coarse: these tests check behaviour, not looks.
const std::vector<std::string> kSmall = {"--size",     "160x120", "--wrinkle-size",      "256", "--samples",
                                         "1",          "--face-resolution", "0.5", "--texture-size", "256"};

class RoughEdges : public ::testing::Test {
protected:
    emoface::testing::ScratchDir scratch_;
};

// --- play --out into a folder that does not exist yet ------------------------

TEST_F(RoughEdges, PlayMakesAMissingOutputFolder) {
    struct Case {
        std::string out;     // under the scratch folder
        std::string first;   // a file it must write
    };
    const Case cases[] = {
        {"frames/%04d.png", "frames/0000.png"},
        {"deeper/still/%04d.png", "deeper/still/0001.png"},
        {"video/demo.avi", "video/demo.avi"},
    };
    for (const Case& c : cases) {
        const CommandResult r =
            run_emoface(args_with({"play", kTour, "--frames", "0:2", "--out", scratch_.path(c.out)}, kSmall));
        EXPECT_EQ(r.exit_code, 0) << c.out << "\n" << r.err;
        EXPECT_TRUE(fs::is_regular_file(scratch_.path(c.first))) << c.out;
    }
}

TEST_F(RoughEdges, PlayChecksEverythingBeforeMakingTheFolder) {
    // A bad slice fails before the folder is made: nothing is left behind.
    const CommandResult r = run_emoface(
        args_with({"play", kTour, "--frames", "60:", "--out", scratch_.path("never/%04d.png")}, kSmall));
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_FALSE(fs::exists(scratch_.path("never")));
}

// --- --frames: the user's text quoted, what is expected said -----------------

TEST_F(RoughEdges, FramesErrorsQuoteTheSlice) {
    struct Case {
        std::string slice, line;
    };
    const Case cases[] = {
        {"60:", "emoface: play: --frames '60:': first frame 60 is past the end (the animation has frames 0..49)\n"},
        {"60::", "emoface: play: --frames '60::': expected A:B (first frame, end frame exclusive), e.g. 0:50, 50: "
                 "or :50\n"},
        {"0:51", "emoface: play: --frames '0:51': end 51 is past the end (the animation has frames 0..49; the end "
                 "is exclusive, so at most 50)\n"},
        {"9:3", "emoface: play: --frames '9:3': expected A < B (the end frame B is exclusive)\n"},
        {"a:3", "emoface: play: --frames 'a:3': expected A:B of frame numbers, 'a' is not one\n"},
        {"-1:3", "emoface: play: --frames '-1:3': expected A:B of frame numbers, '-1' is not one\n"},
    };
    for (const Case& c : cases) {
        const CommandResult r =
            run_emoface(args_with({"play", kTour, "--frames=" + c.slice, "--out", scratch_.path("%04d.png")}, kSmall));
        EXPECT_EQ(r.exit_code, 2) << c.slice;
        EXPECT_EQ(r.err, c.line) << c.slice;
    }
}

// --- usage lines name the command, not the binary's path ---------------------

TEST_F(RoughEdges, UsageLinesSayEmoface) {
    for (const std::string command : {"play", "inspect", "info"}) {
        const CommandResult r = run_emoface({command, "--help"});
        EXPECT_EQ(r.exit_code, 0) << command;
        EXPECT_NE(r.out.find("\nUsage: emoface " + command + " "), std::string::npos) << r.out.substr(0, 200);
        EXPECT_EQ(r.out.find('/' + std::string("emoface")), std::string::npos) << r.out.substr(0, 200);
    }
}

// --- info: FAP 1 and FAP 2 content -------------------------------------------

TEST_F(RoughEdges, InfoReportsWhatFap2Drives) {
    const CommandResult r = run_emoface({"info", kDemoTour});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    // demo_tour drives the six emotions through FAP 2 alone.
    EXPECT_NE(r.out.find("  moving    6 expressions (FAP 2); no low-level FAP\n"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("moving    none"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("  FAP 2     420 frames, 6 expressions (intensity 0..63; frames counted from 0):\n"),
              std::string::npos)
        << r.out;
    for (const char* emotion : {"joy", "sadness", "anger", "fear", "disgust", "surprise"})
        EXPECT_NE(r.out.find(std::string("    ") + emotion), std::string::npos) << emotion << "\n" << r.out;
    EXPECT_NE(r.out.find("  FAP 1     not used\n"), std::string::npos) << r.out;
}

TEST_F(RoughEdges, InfoListsVisemesAndExpressionsWithTheirFrames) {
    // Frame 0: viseme 1 (p b m) and joy at 20; frame 1: viseme 10 (A:) over 1,
    // joy at 40 and anger at 10; frame 2: anger at 63.
    std::string mask(68 * 2, ' ');
    for (int i = 0; i < 68; ++i) mask[std::size_t(2 * i)] = i < 2 ? '1' : '0';
    mask.pop_back();
    const std::string fap = scratch_.write("codes.fap", "2.1 codes 25 3\n" + mask + "\n0 1 0 0 0 1 20 0 0 0 0\n" +
                                                             mask + "\n1 10 1 32 0 1 40 3 10 0 0\n" + mask +
                                                             "\n2 0 0 0 0 3 63 0 0 0 0\n");
    const CommandResult r = run_emoface({"info", fap});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string expected =
        "  moving    2 visemes (FAP 1), 2 expressions (FAP 2); no low-level FAP\n"
        "  FAP 1     3 frames, 2 visemes (frames counted from 0):\n"
        "     1 p b m     2 frames in 0..1\n"
        "    10 A:        1 frame in 1..1\n"
        "  FAP 2     3 frames, 2 expressions (intensity 0..63; frames counted from 0):\n"
        "    joy       intensity 20..40  2 frames in 0..1\n"
        "    anger     intensity 10..63  2 frames in 1..2\n";
    EXPECT_NE(r.out.find(expected), std::string::npos) << r.out;
}

// --- inspect: stage timings, the title ---------------------------------------

TEST_F(RoughEdges, InspectPrintsItsStageTimings) {
    const CommandResult r = run_emoface(args_with({"inspect", "--mix", "sadness", "--out", scratch_.path("a.png")},
                                                  {"--size", "160x160", "--wrinkle-size", "256", "--samples", "1",
                                                   "--face-resolution", "0.5", "--texture-size", "256"}));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("  load "), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("per frame, mean of 1:"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("| draw "), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("glFinish"), std::string::npos) << r.out;
}

// --- the AU line (info, inspect's title, the viewer) --------------------------

TEST(AuLabel, FormatsTheAusShownInInfoInspectAndTheViewer) {
    using emoface::expression::AuIntensities;
    struct Case {
        const char* what;
        std::vector<std::array<double, 3>> aus;  // number, left, right
        std::string expected;
    };
    const std::vector<Case> cases = {
        {"empty", {}, "none"},
        {"all under 0.1", {{4, 0.09, 0.09}, {12, 0.05, 0.0}}, "none"},
        {"equal sides: one term", {{12, 0.8, 0.8}}, "0.8 AU12"},
        {"unequal sides: L and R", {{12, 0.8, 0.5}}, "0.8 AU12L + 0.5 AU12R"},
        {"one side under 0.1", {{6, 0.7, 0.05}}, "0.7 AU6L"},
        {"0.1 itself is shown", {{1, 0.1, 0.1}}, "0.1 AU1"},
        {"number order, small ones out", {{26, 1.0, 1.0}, {4, 0.3, 0.3}, {15, 0.02, 0.02}, {1, 1.0, 1.0}},
         "1 AU1 + 0.3 AU4 + 1 AU26"},
    };
    for (const Case& c : cases) {
        AuIntensities a;
        for (const auto& [n, l, r] : c.aus) {
            a.left[std::size_t(n)] = l;
            a.right[std::size_t(n)] = r;
        }
        EXPECT_EQ(emoface::apps::au_label(a), c.expected) << c.what;
    }
}

// inspect's title: where the emotion mix was derived from the AUs, the AUs
// are the frame's description and the mix is labelled derived (issue 11: a
// state of AU4 read as "mix 0.2 sadness + 0.1 anger").
TEST(FrameTitle, NamesTheAusFirstWhereTheMixWasDerivedFromThem) {
    using emoface::apps::frame_title;
    using emoface::expression::Emotion;
    using emoface::expression::EmotionMix;
    using emoface::expression::FaceState;
    using emoface::expression::MixSource;
    FaceState derived;
    derived.aus.left[4] = derived.aus.right[4] = 1.0;
    derived.mix[Emotion::Sadness] = 0.2;
    derived.mix[Emotion::Anger] = 0.1;
    derived.mix_source = MixSource::FromActionUnits;
    EmotionMix au4;
    au4.aus.left[4] = au4.aus.right[4] = 1.0;
    EmotionMix joy_au4 = au4;
    joy_au4[Emotion::Joy] = 0.6;
    FaceState given;
    given.aus.left[4] = given.aus.right[4] = 0.5;
    given.mix[Emotion::Sadness] = 1.0;
    given.mix_source = MixSource::Given;
    FaceState expression = given;
    expression.mix_source = MixSource::Expression;
    EmotionMix sadness;
    sadness[Emotion::Sadness] = 1.0;

    struct Case {
        const char* what;
        std::string where;
        const FaceState& state;
        const EmotionMix* given;
        std::string first, second;
    };
    const std::string derived_line = "derived mix 0.20 sadness + 0.10 anger (from the AUs; it drives the wrinkles)";
    const Case cases[] = {
        {"--mix AU4", "", derived, &au4, "AUs 1 AU4", derived_line},
        {"--mix 0.6 joy + AU4", "", derived, &joy_au4, "mix 0.60 joy + 1 AU4   AUs 1 AU4", derived_line},
        {"a frame of low-level FAPs", "tour.fap frame 12/49", derived, nullptr, "tour.fap frame 12/49   AUs 1 AU4",
         derived_line},
        {"--mix sadness", "", given, &sadness, "mix 1.00 sadness", "AUs: 0.5 AU4"},
        {"a frame of FAP 2", "tour.fap frame 3/49", expression, nullptr,
         "tour.fap frame 3/49   mix 1.00 sadness [expression (FAP 2)]", "AUs: 0.5 AU4"},
    };
    for (const Case& c : cases) {
        const auto title = frame_title(c.where, c.state, c.given);
        EXPECT_EQ(title.first, c.first) << c.what;
        EXPECT_EQ(title.second, c.second) << c.what;
    }
}

// --- label placement ---------------------------------------------------------

bool inside(const cv::Rect& box, cv::Size image) { return (box & cv::Rect(0, 0, image.width, image.height)) == box; }

// Every placed pair apart, every box inside, no box over a dot.
void expect_legible(const std::vector<LabelRequest>& requests, cv::Size image, const char* what) {
    const auto placed = place_labels(requests, image);
    ASSERT_EQ(placed.size(), requests.size());
    for (std::size_t i = 0; i < placed.size(); ++i) {
        if (!placed[i]) continue;
        const cv::Rect& a = placed[i]->box;
        EXPECT_TRUE(inside(a, image)) << what << ": label " << i << " at " << a;
        EXPECT_EQ(a.size(), requests[i].size) << what;
        for (std::size_t j = 0; j < requests.size(); ++j) {
            const cv::Point2f p = requests[j].point;
            EXPECT_FALSE(a.contains(cv::Point(int(p.x), int(p.y)))) << what << ": label " << i << " hides dot " << j;
            if (j > i && placed[j]) EXPECT_EQ((a & placed[j]->box).area(), 0) << what << ": labels " << i << ", " << j;
        }
    }
}

TEST(LabelPlacement, ClustersEdgesAndCornersStayLegible) {
    struct Case {
        const char* what;
        cv::Size image;
        std::vector<cv::Point2f> points;
        bool all_placed;
    };
    std::vector<cv::Point2f> eye, edges, grid;
    for (int i = 0; i < 12; ++i) eye.push_back({240.0f + 3.0f * float(i % 4), 200.0f + 3.0f * float(i / 4)});
    edges = {{0, 0}, {479, 0}, {0, 479}, {479, 479}, {240, 0}, {0, 240}, {479, 240}, {240, 479}};
    for (int y = 0; y < 10; ++y)
        for (int x = 0; x < 10; ++x) grid.push_back({10.0f + 14.0f * float(x), 10.0f + 9.0f * float(y)});
    const Case cases[] = {
        {"an eye's dozen points within 10 px", {480, 480}, eye, true},
        {"points on the edges and corners", {480, 480}, edges, true},
        {"a hundred points crammed into a small picture", {160, 100}, grid, false},
    };
    for (const Case& c : cases) {
        std::vector<LabelRequest> requests;
        for (const auto& p : c.points) requests.push_back({p, cv::Size(24, 11)});
        expect_legible(requests, c.image, c.what);
        if (c.all_placed) {
            const auto placed = place_labels(requests, c.image);
            EXPECT_TRUE(std::all_of(placed.begin(), placed.end(), [](const auto& p) { return p.has_value(); }))
                << c.what;
        }
    }
}

// The real overlay: inspect's two panels (render and wrinkle map) of the
// demo tour's busiest expression, at the README's size.
TEST(LabelPlacement, InspectLabelsOfTheFaceDoNotOverlap) {
    emoface::apps::SessionOptions o;
    o.width = o.height = 480;
    o.samples = 1;
    o.wrinkle_size = 256;
    o.face_resolution = 0.5;
    o.texture_size = 256;
    o.backend = emoface::morph::Backend::Cpu;
    emoface::apps::Session session(o);
    emoface::expression::EmotionMix mix;
    mix[emoface::expression::Emotion::Anger] = 0.7;
    mix[emoface::expression::Emotion::Fear] = 0.3;
    session.update(session.face_state(mix));
    const auto camera = session.draw_options(1.0f).camera;
    const cv::Size image(480, 480);
    const std::array<std::optional<glm::vec2>, 84> panels[] = {
        session.screen_points(camera, image.width, image.height),
        emoface::apps::layout_pixels(session.layout(), image.width, image.height),
    };
    for (const auto& points : panels) {
        const std::vector<FeatureLabel> labels = emoface::apps::feature_labels(points, image);
        const auto present = std::count_if(points.begin(), points.end(), [](const auto& p) { return bool(p); });
        EXPECT_EQ(std::ptrdiff_t(labels.size()), present) << "every point keeps its label at 480x480";
        for (std::size_t i = 0; i < labels.size(); ++i) {
            EXPECT_TRUE(inside(labels[i].box, image)) << labels[i].text << " at " << labels[i].box;
            for (std::size_t j = i + 1; j < labels.size(); ++j)
                EXPECT_EQ((labels[i].box & labels[j].box).area(), 0) << labels[i].text << " and " << labels[j].text;
        }
    }
}

}  // namespace
