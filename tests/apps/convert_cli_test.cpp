// `emoface convert` and `emoface info` on capture files, end to end: the
// built binary on CSVs written here, the FAP files it writes read back, round
// trips through the command, and bad input (one line, exit 2, no file).
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "emoface/fap/fap_io.h"
#include "support/run_emoface.h"
#include "support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using emoface::testing::CommandResult;
using emoface::testing::run_emoface;

const std::string kTour = std::string(EMOFACE_DATA_DIR) + "/fap/tour.fap";

const char* const kShapes[] = {
    "EyeBlinkLeft",     "EyeLookDownLeft",    "EyeLookInLeft",       "EyeLookOutLeft",    "EyeLookUpLeft",
    "EyeSquintLeft",    "EyeWideLeft",        "EyeBlinkRight",       "EyeLookDownRight",  "EyeLookInRight",
    "EyeLookOutRight",  "EyeLookUpRight",     "EyeSquintRight",      "EyeWideRight",      "JawForward",
    "JawLeft",          "JawRight",           "JawOpen",             "MouthClose",        "MouthFunnel",
    "MouthPucker",      "MouthLeft",          "MouthRight",          "MouthSmileLeft",    "MouthSmileRight",
    "MouthFrownLeft",   "MouthFrownRight",    "MouthDimpleLeft",     "MouthDimpleRight",  "MouthStretchLeft",
    "MouthStretchRight", "MouthRollLower",    "MouthRollUpper",      "MouthShrugLower",   "MouthShrugUpper",
    "MouthPressLeft",   "MouthPressRight",    "MouthLowerDownLeft",  "MouthLowerDownRight", "MouthUpperUpLeft",
    "MouthUpperUpRight", "BrowDownLeft",      "BrowDownRight",       "BrowInnerUp",       "BrowOuterUpLeft",
    "BrowOuterUpRight", "CheekPuff",          "CheekSquintLeft",     "CheekSquintRight",  "NoseSneerLeft",
    "NoseSneerRight",   "TongueOut"};

// One second at 30 rows a second: a smile growing, brows down, the head turning.
std::string live_link_csv() {
    std::string out = "Timecode,BlendShapeCount";
    for (const char* s : kShapes) out += std::string(",") + s;
    out += ",HeadYaw,HeadPitch,HeadRoll,LeftEyeYaw,LeftEyePitch,LeftEyeRoll,RightEyeYaw,RightEyePitch,RightEyeRoll\n";
    for (int i = 0; i < 30; ++i) {
        out += fmt::format("12:00:00:{:02}.000,61", i);
        for (const std::string s : kShapes) {
            double w = 0;
            if (s == "MouthSmileLeft" || s == "MouthSmileRight") w = i / 29.0;
            if (s == "BrowDownLeft" || s == "BrowDownRight") w = 0.6;
            out += fmt::format(",{}", w);
        }
        out += fmt::format(",{},0,0,0,0,0,0,0,0\n", 0.01 * i);
    }
    return out;
}

// OpenFace 2.0 with leading spaces in its header, a lost row.
std::string openface_csv() {
    std::string out = "frame, face_id, timestamp, confidence, success, gaze_angle_x, gaze_angle_y, pose_Rx, pose_Ry, "
                      "pose_Rz, AU01_r, AU02_r, AU04_r, AU06_r, AU12_r, AU26_r\n";
    for (int i = 0; i < 25; ++i)
        out += fmt::format("{}, 0, {:.2f}, 0.97, {}, 0.1, 0, 0, 0.1, 0, {:.2f}, {:.2f}, 0, 0, 0, 1\n", i + 1, i * 0.04,
                           i == 10 ? 0 : 1, i * 0.2, i * 0.1);
    return out;
}

class ConvertCli : public ::testing::Test {
protected:
    std::string path(const std::string& name) const { return scratch_.path(name); }
    std::string write(const std::string& name, const std::string& text) const { return scratch_.write(name, text); }
    emoface::testing::ScratchDir scratch_;
};

TEST_F(ConvertCli, CapturesBecomeFapFilesThatInfoReads) {
    for (const auto& [name, text, format, fps, frames] :
         std::vector<std::tuple<std::string, std::string, std::string, double, std::size_t>>{
             {"take.csv", live_link_csv(), "Live Link Face CSV", 30, 30},
             {"openface.csv", openface_csv(), "OpenFace 2.0 CSV", 25, 25}}) {
        const std::string in = write(name, text), out = path(name + ".fap");
        CommandResult r = run_emoface({"convert", in, out});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        EXPECT_NE(r.out.find(fmt::format("({}, {} frames at {:g} fps) -> {} (FAP)", format, frames, fps, out)),
                  std::string::npos)
            << r.out;
        // The FAP reader takes it without a warning (Xface's and Greta's rules:
        // header, 68-token masks, values in FAP order).
        const emoface::fap::FapStream s = emoface::fap::read_fap_file(out);
        EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
        EXPECT_EQ(s.frames.size(), frames);
        EXPECT_EQ(s.fps, fps);
        r = run_emoface({"info", "--json", out});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        const nlohmann::json j = nlohmann::json::parse(r.out);
        EXPECT_EQ(j[0]["frames"], frames);
        EXPECT_EQ(j[0]["format"], "FAP");
        // info reads the capture itself too, naming its format.
        r = run_emoface({"info", "--json", in});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        EXPECT_EQ(nlohmann::json::parse(r.out)[0]["format"], format);
    }
}

TEST_F(ConvertCli, InfoShowsTheCapturedAus) {
    const CommandResult r = run_emoface({"info", write("take.csv", live_link_csv())});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("  format    Live Link Face CSV"), std::string::npos) << r.out;
    // The smile and the lowered brows (their peaks).
    EXPECT_NE(r.out.find("1 AU12"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("0.6 AU4"), std::string::npos) << r.out;
}

TEST_F(ConvertCli, RoundTripsThroughEveryFormat) {
    // FAP -> ARKit CSV -> FAP -> OpenFace CSV -> FAP: the face's AUs survive
    // within 0.05 of FACS E (what the formats share: the AU layer).
    const std::string in = write("take.csv", live_link_csv());
    ASSERT_EQ(run_emoface({"convert", in, path("a.fap")}).exit_code, 0);
    CommandResult r = run_emoface({"convert", path("a.fap"), path("b.csv"), "--to", "arkit"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    ASSERT_EQ(run_emoface({"convert", path("b.csv"), path("c.fap")}).exit_code, 0);
    r = run_emoface({"convert", path("c.fap"), path("d.csv"), "--to", "openface"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    ASSERT_EQ(run_emoface({"convert", path("d.csv"), path("e.fap")}).exit_code, 0);
    for (const char* f : {"a.fap", "c.fap", "e.fap"}) {
        r = run_emoface({"info", "--json", "--frame", "29", path(f)});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        const nlohmann::json aus = nlohmann::json::parse(r.out)[0]["action_units"]["intensities"];
        EXPECT_NEAR(aus.value("AU12L", 0.0), 1.0, 0.05) << f << " " << aus.dump();
        EXPECT_NEAR(aus.value("AU4R", 0.0), 0.6, 0.05) << f << " " << aus.dump();
    }
    // FAP -> FAP is the file itself.
    ASSERT_EQ(run_emoface({"convert", kTour, path("tour.fap")}).exit_code, 0);
    EXPECT_TRUE(emoface::fap::same_content(emoface::fap::read_fap_file(kTour), emoface::fap::read_fap_file(path("tour.fap"))));
}

TEST_F(ConvertCli, BadInputIsOneLineAndNoFile) {
    const std::string truncated = live_link_csv().substr(0, live_link_csv().size() - 30);
    struct Case {
        std::vector<std::string> args;
        std::string message;
    };
    const std::string in = write("take.csv", live_link_csv());
    const std::string cut = write("cut.csv", truncated);
    const std::string other = write("points.csv", "x,y,z\n1,2,3\n");
    const std::vector<Case> cases{
        {{"convert", cut, path("out.fap")},
         "emoface: capture: " + cut + ":31: expected 63 comma-separated fields, as the header on line 1 has, found 50\n"},
        {{"convert", other, path("out.fap")}, "expected a FAP file, or a CSV whose header is OpenFace 2.0's"},
        {{"convert", in, path("out.csv")},
         "emoface: convert: " + path("out.csv") +
             ": a .csv may be an ARKit (Live Link Face) or an OpenFace CSV: say which with --to arkit or --to "
             "openface\n"},
        {{"convert", in, path("out.fap"), "--to", "glb"}, "emoface: convert: --to 'glb': expected fap, arkit or openface\n"},
        {{"convert", in, path("out.txt")}, "expected an output ending in .fap, or --to fap, arkit or openface\n"},
    };
    for (const Case& c : cases) {
        const CommandResult r = run_emoface(c.args);
        EXPECT_EQ(r.exit_code, 2) << r.err;
        EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_FALSE(fs::exists(path("out.fap")));
        EXPECT_FALSE(fs::exists(path("out.csv")));
    }
}

}  // namespace
