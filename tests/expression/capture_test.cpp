// Capture data as FAP streams (expression/capture.h): OpenFace 2.0, Live Link
// Face and MediaPipe CSVs built here row by row, what each column drives, the
// malformed-input table, and round trips through the writers.
#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "emoface/common/error.h"
#include "emoface/expression/capture.h"
#include "emoface/expression/face_state.h"
#include "emoface/expression/profiles.h"
#include "emoface/fap/fap_io.h"
#include "support/expect_error.h"

namespace {

namespace ex = emoface::expression;
namespace fap = emoface::fap;
using emoface::InputError;
using emoface::testing::expect_error;
using emoface::testing::thrown_message;

const std::string kData = EMOFACE_DATA_DIR;

const ex::CaptureTables& tables() {
    static const ex::CaptureTables t = ex::load_capture_tables(kData);
    return t;
}
const ex::EmotionProfiles& emotions() {
    static const ex::EmotionProfiles e = ex::load_emotion_profiles(kData + "/expression/emotions.json");
    return e;
}
const ex::VisemeProfiles& visemes() {
    static const ex::VisemeProfiles v = ex::load_viseme_profiles(kData + "/expression/visemes.json");
    return v;
}

fap::FapStream parse(const std::string& text, ex::AnimationFormat* format = nullptr) {
    ex::Animation a = ex::parse_animation(text, "take.csv", kData);
    if (format) *format = a.format;
    return a.stream;
}

// --- sample files ------------------------------------------------------------

const std::vector<int> kOpenFaceAus{1, 2, 4, 5, 6, 7, 9, 10, 12, 14, 15, 17, 20, 23, 25, 26, 45};

struct OpenFaceRow {
    double time = 0;
    std::map<int, double> aus;  // AU number -> 0..5
    double rx = 0, ry = 0, rz = 0, gx = 0, gy = 0;
    int success = 1;
    double confidence = 0.98;
};

// As OpenFace 2.0's FeatureExtraction writes it: ", " between fields (older
// versions' header names then start with a space), landmark columns too.
std::string openface_csv(const std::vector<OpenFaceRow>& rows) {
    std::string out = "frame, face_id, timestamp, confidence, success, gaze_0_x, gaze_angle_x, gaze_angle_y, x_0, "
                      "pose_Tx, pose_Rx, pose_Ry, pose_Rz";
    for (int au : kOpenFaceAus) out += fmt::format(", AU{:02}_r", au);
    out += ", AU28_c\n";
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const OpenFaceRow& r = rows[i];
        out += fmt::format("{}, 0, {:.3f}, {}, {}, 0.1, {}, {}, 312.5, 20.1, {}, {}, {}", i + 1, r.time, r.confidence,
                           r.success, r.gx, r.gy, r.rx, r.ry, r.rz);
        for (int au : kOpenFaceAus) out += fmt::format(", {:.2f}", r.aus.count(au) ? r.aus.at(au) : 0.0);
        out += ", 0\n";
    }
    return out;
}

const std::vector<std::string>& shapes() { return ex::arkit_shape_names(); }

std::string camel(std::string s) {
    s[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(s[0])));
    return s;
}

struct ArkitRow {
    std::string time;  // Timecode, or the time column's text
    std::map<std::string, double> w;  // PascalCase shape -> coefficient
    std::map<std::string, double> angles;
};

std::string live_link_csv(const std::vector<ArkitRow>& rows) {
    const std::vector<std::string> angles{"HeadYaw",     "HeadPitch",    "HeadRoll",
                                          "LeftEyeYaw",  "LeftEyePitch", "LeftEyeRoll",
                                          "RightEyeYaw", "RightEyePitch", "RightEyeRoll"};
    std::string out = "Timecode,BlendShapeCount";
    for (const auto& s : shapes()) out += "," + s;
    for (const auto& a : angles) out += "," + a;
    out += "\n";
    for (const ArkitRow& r : rows) {
        out += r.time + ",61";
        for (const auto& s : shapes()) out += fmt::format(",{}", r.w.count(s) ? r.w.at(s) : 0.0);
        for (const auto& a : angles) out += fmt::format(",{}", r.angles.count(a) ? r.angles.at(a) : 0.0);
        out += "\n";
    }
    return out;
}

// As people dump MediaPipe Face Landmarker results: _neutral and the 51
// shapes it has (no tongue) in its camelCase, after a time column.
std::string mediapipe_csv(const std::string& time_column, const std::vector<ArkitRow>& rows) {
    std::string out = time_column + ",_neutral";
    for (const auto& s : shapes())
        if (s != "TongueOut") out += "," + camel(s);
    out += "\n";
    for (const ArkitRow& r : rows) {
        out += r.time + ",0.5";
        for (const auto& s : shapes())
            if (s != "TongueOut") out += fmt::format(",{}", r.w.count(s) ? r.w.at(s) : 0.0);
        out += "\n";
    }
    return out;
}

std::string timecode(int frame30, int sub = 0) {
    return fmt::format("10:{:02}:{:02}:{:02}.{:03}", frame30 / 1800 % 60, frame30 / 30 % 60, frame30 % 30, sub);
}

ex::FapValues au_faps(std::map<std::string, double> terms) {
    ex::AuIntensities in;
    for (const auto& [t, w] : terms) {
        std::string err;
        const auto term = ex::parse_au_term(t, &err);
        if (term->side != ex::AuSide::Right) in.left[term->number] = w;
        if (term->side != ex::AuSide::Left) in.right[term->number] = w;
    }
    return tables().aus.faps(in);
}

// --- OpenFace ------------------------------------------------------------------

TEST(OpenFaceCsv, AusPoseAndGazeBecomeFaps) {
    OpenFaceRow a, b;
    a.time = 0;
    b.time = 1.0 / 30;
    b.aus = {{12, 5.0}, {6, 2.5}, {1, 1.0}};
    b.rx = 0.1;   // head tipped down
    b.ry = 0.2;   // turned to its own right
    b.rz = 0.05;  // top towards its left
    b.gx = 0.3;   // looking to its left
    b.gy = -0.1;  // and up
    ex::AnimationFormat format{};
    const fap::FapStream s = parse(openface_csv({a, b}), &format);
    EXPECT_EQ(format, ex::AnimationFormat::OpenFace);
    EXPECT_EQ(s.fps, 30);
    ASSERT_EQ(s.frames.size(), 2u);
    const ex::FapValues want = au_faps({{"AU12", 1.0}, {"AU6", 0.5}, {"AU1", 0.2}});
    const fap::FapFrame& f = s.frames[1];
    for (int n : {12, 13, 59, 41, 42, 31, 33, 19}) EXPECT_NEAR(f.get(n), want[n - 1], 1e-9) << "FAP " << n;
    EXPECT_NEAR(f.get(48), 10000, 1e-6);   // head_pitch + = down
    EXPECT_NEAR(f.get(49), -20000, 1e-6);  // head_yaw - = to the face's right
    EXPECT_NEAR(f.get(50), -5000, 1e-6);   // head_roll - = tilt left (AU55)
    EXPECT_NEAR(f.get(23), 30000, 1e-6);   // both eyes to the face's left
    EXPECT_NEAR(f.get(24), 30000, 1e-6);
    EXPECT_NEAR(f.get(25), -10000, 1e-6);  // up
    // Every AU column's FAPs are transmitted from the first frame, at rest there.
    EXPECT_TRUE(s.frames[0].has(12));
    EXPECT_EQ(s.frames[0].get(12), 0.0);
    EXPECT_FALSE(s.frames[0].has(15));  // shift_jaw: no OpenFace AU moves it
}

TEST(OpenFaceCsv, ThePlayedAusAreTheCapturedOnes) {
    // The AU layer reads the capture's AUs back from its FAPs (face_state).
    OpenFaceRow a;
    a.aus = {{1, 4.0}, {2, 4.0}, {4, 0.0}, {12, 3.0}, {26, 2.0}};
    const fap::FapStream s = parse(openface_csv({a}));
    const ex::FaceState state = ex::face_state(fap::resolve_untransmitted(s).frames[0], emotions());
    for (const auto& [au, v] : a.aus) {
        EXPECT_NEAR(state.aus.left[au], v / 5, 0.02) << "AU" << au;
        EXPECT_NEAR(state.aus.right[au], v / 5, 0.02) << "AU" << au;
    }
}

TEST(OpenFaceCsv, LostTrackingHoldsTheLastGoodRow) {
    std::vector<OpenFaceRow> rows(5);
    for (int i = 0; i < 5; ++i) {
        rows[std::size_t(i)].time = i * 0.04;
        rows[std::size_t(i)].aus = {{12, double(i)}};
    }
    rows[0].success = 0;           // before any good row: the first good row's
    rows[2].success = 0;           // face lost: holds row 1
    rows[3].confidence = 0.2;      // tracked, but not to be trusted: holds row 1
    const fap::FapStream s = parse(openface_csv(rows));
    ASSERT_EQ(s.frames.size(), 5u);
    const double per = tables().aus.find(12)->faps[11] / 5;  // raise_l_cornerlip per OpenFace unit
    const std::vector<double> want{1, 1, 1, 1, 4};
    for (std::size_t k = 0; k < 5; ++k) EXPECT_NEAR(s.frames[k].get(12), want[k] * per, 1e-9) << "frame " << k;
    ASSERT_EQ(s.warnings.size(), 1u);
    EXPECT_EQ(s.warnings[0],
              "take.csv: 3 of 5 rows have success 0 or confidence under 0.5: they hold the last good row's values");
}

TEST(OpenFaceCsv, IrregularRowsAreResampledAtTheMedianRate) {
    // 25 rows a second with one dropped: frames at 1/25 s, the gap interpolated.
    std::vector<OpenFaceRow> rows;
    for (int i : {0, 1, 2, 4, 5}) {
        OpenFaceRow r;
        r.time = i * 0.04;
        r.aus = {{26, double(i)}};
        rows.push_back(r);
    }
    const fap::FapStream s = parse(openface_csv(rows));
    EXPECT_DOUBLE_EQ(s.fps, 25);
    ASSERT_EQ(s.frames.size(), 6u);
    const double per = tables().aus.find(26)->faps[2] / 5;  // open_jaw
    for (std::size_t k = 0; k < 6; ++k) EXPECT_NEAR(s.frames[k].get(3), double(k) * per, 1e-6) << "frame " << k;
}

// --- ARKit ---------------------------------------------------------------------

TEST(LiveLinkFaceCsv, ShapesAndAnglesBecomeFaps) {
    // 60 rows a second on a 30 fps timecode: subframes .500.
    std::vector<ArkitRow> rows;
    for (int i = 0; i < 70; ++i) {
        ArkitRow r;
        r.time = timecode(100 + i / 2, i % 2 ? 500 : 0);
        r.w = {{"MouthSmileLeft", 0.8}, {"JawLeft", 0.5}, {"EyeLookOutLeft", 1.0}};
        r.angles = {{"HeadYaw", 0.25}, {"LeftEyeYaw", 0.1}, {"LeftEyeRoll", 0.3}};
        rows.push_back(r);
    }
    ex::AnimationFormat format{};
    const fap::FapStream s = parse(live_link_csv(rows), &format);
    EXPECT_EQ(format, ex::AnimationFormat::LiveLinkFace);
    EXPECT_DOUBLE_EQ(s.fps, 60);
    ASSERT_EQ(s.frames.size(), 70u);
    EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
    const ex::FapValues smile = au_faps({{"AU12L", 0.8}});
    const fap::FapFrame& f = s.frames[3];
    EXPECT_NEAR(f.get(12), smile[11], 1e-9);  // raise_l_cornerlip
    EXPECT_NEAR(f.get(13), 0.0, 1e-9);        // the right corner stays
    EXPECT_NEAR(f.get(15), -75, 1e-9);        // shift_jaw: half of JawLeft's -150
    EXPECT_NEAR(f.get(49), 25000, 1e-6);      // head_yaw from HeadYaw
    // The measured eye angle wins over EyeLookOutLeft's share.
    EXPECT_NEAR(f.get(23), 10000, 1e-6);
}

TEST(LiveLinkFaceCsv, TimecodeRateComesFromItsFrameFields) {
    // 25 fps timecode, one row per timecode frame, across a second: 25 fps.
    std::vector<ArkitRow> rows;
    for (int i = 0; i < 30; ++i)
        rows.push_back({fmt::format("00:00:{:02}:{:02}.000", 1 + i / 25, i % 25), {{"JawOpen", i / 30.0}}, {}});
    const fap::FapStream s = parse(live_link_csv(rows));
    EXPECT_DOUBLE_EQ(s.fps, 25);
    EXPECT_EQ(s.frames.size(), 30u);
}

TEST(MediaPipeCsv, CamelCaseShapesWithATimeColumn) {
    std::vector<ArkitRow> rows;
    for (int i = 0; i < 4; ++i)
        rows.push_back({fmt::format("{}", 1000 + i * 40), {{"BrowInnerUp", 0.25 * i}, {"NoseSneerRight", 0.5}}, {}});
    ex::AnimationFormat format{};
    const fap::FapStream s = parse(mediapipe_csv("timestamp_ms", rows), &format);
    EXPECT_EQ(format, ex::AnimationFormat::MediaPipe);
    EXPECT_DOUBLE_EQ(s.fps, 25);
    ASSERT_EQ(s.frames.size(), 4u);
    const ex::FapValues want = au_faps({{"AU1", 0.75}, {"AU9R", 0.5}});
    for (int n : {31, 32, 33, 62, 63}) EXPECT_NEAR(s.frames[3].get(n), want[n - 1], 1e-9) << "FAP " << n;
}

TEST(MediaPipeCsv, AFrameColumnPlaysAtThirtyFramesPerSecond) {
    std::vector<ArkitRow> rows;
    for (int i = 0; i < 3; ++i) rows.push_back({fmt::format("{}", i), {{"JawOpen", 0.5}}, {}});
    const fap::FapStream s = parse(mediapipe_csv("frame", rows));
    EXPECT_DOUBLE_EQ(s.fps, 30);
    ASSERT_EQ(s.warnings.size(), 1u);
    EXPECT_EQ(s.warnings[0], "take.csv:1: timing from column frame at 30 frames per second (no time column)");
}

TEST(AnimationFile, AFapFileIsReadAsOne) {
    std::string mask;
    for (int i = 0; i < 68; ++i) mask += i == 2 ? "1 " : "0 ";
    ex::AnimationFormat format = ex::AnimationFormat::OpenFace;
    // Commas in its comments and its name do not make it a CSV.
    const fap::FapStream s = parse("# joy, then anger\n2.1 a, b 25 1\n" + mask + "\n0 120\n", &format);
    EXPECT_EQ(format, ex::AnimationFormat::Fap);
    ASSERT_EQ(s.frames.size(), 1u);
    EXPECT_EQ(s.frames[0].get(3), 120);
    EXPECT_EQ(s.name, "a, b");
}

TEST(ArkitTable, EveryShapeMovesTheFaceAndLeftMirrorsRight) {
    const ex::ArkitShapes& a = tables().arkit;
    ASSERT_EQ(a.faps.size(), 52u);
    // FAP pairs (left, right) whose + means the same motion on both sides.
    const std::vector<std::pair<int, int>> same{{12, 13}, {59, 60}, {31, 32}, {33, 34}, {35, 36}, {19, 20}, {21, 22},
                                                {41, 42}, {8, 9},   {10, 11}, {55, 56}, {57, 58}, {61, 62}, {25, 26}};
    for (std::size_t i = 0; i < shapes().size(); ++i) {
        const std::string& name = shapes()[i];
        const auto left = name.find("Left");
        if (left == std::string::npos) continue;
        const std::string mirror = name.substr(0, left) + "Right" + name.substr(left + 4);
        const auto j = std::size_t(std::find(shapes().begin(), shapes().end(), mirror) - shapes().begin());
        ASSERT_LT(j, shapes().size()) << mirror;
        for (auto [l, r] : same) {
            EXPECT_NEAR(a.faps[i][l - 1], a.faps[j][r - 1], 1e-9) << name << " FAP " << l;
            EXPECT_NEAR(a.faps[i][r - 1], a.faps[j][l - 1], 1e-9) << name << " FAP " << r;
        }
    }
}

// --- malformed input -------------------------------------------------------------

struct Bad {
    const char* name;
    std::function<std::string()> text;
    std::string message;
};

std::string openface_two_rows() {
    OpenFaceRow a, b;
    b.time = 0.04;
    return openface_csv({a, b});
}

std::string replace_once(std::string s, const std::string& from, const std::string& to) {
    const auto at = s.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) s.replace(at, from.size(), to);
    return s;
}

std::vector<ArkitRow> two_live_link_rows() { return {{timecode(0), {}, {}}, {timecode(1), {}, {}}}; }

const std::vector<Bad>& bad_inputs() {
    static const std::vector<Bad> table{
        {"OpenFaceWithoutSuccess",
         [] { return replace_once(openface_two_rows(), "success", "succes"); },
         "capture: take.csv:1: expected the columns of a OpenFace 2.0 CSV (the file resembles one), found no success"},
        {"LiveLinkWithoutAShape",
         [] { return replace_once(live_link_csv(two_live_link_rows()), "MouthPucker", "MouthPuker"); },
         "capture: take.csv:1: expected the columns of a Live Link Face CSV (the file resembles one), found no "
         "MouthPucker"},
        {"MediaPipeWithoutTime",
         [] { return replace_once(mediapipe_csv("timestamp_ms", {{"0", {}, {}}}), "timestamp_ms", "when"); },
         "capture: take.csv:1: expected the columns of a MediaPipe blendshape CSV (the file resembles one), found no "
         "a time column (timestamp_ms, time_ms, timestamp, time, seconds, time_s or frame)"},
        {"NaN",
         [] { return replace_once(openface_two_rows(), "0.040,", "nan,"); },
         "capture: take.csv:3: expected a finite number in column timestamp, found \"nan\""},
        {"NaNCoefficient",
         [] { return mediapipe_csv("time", {{"0", {{"JawOpen", NAN}}, {}}}); },
         "capture: take.csv:2: expected a finite number in column jawOpen, found \"nan\""},
        {"RowsOutOfTimeOrder",
         [] {
             OpenFaceRow a, b, c;
             a.time = 0.04, b.time = 0.08, c.time = 0.06;
             return openface_csv({a, b, c});
         },
         "capture: take.csv:4: expected a timestamp later than the row before's 0.08, found 0.06 (rows out of time "
         "order)"},
        {"TimecodesOutOfOrder",
         [] { return live_link_csv({{timecode(5), {}, {}}, {timecode(4), {}, {}}}); },
         "capture: take.csv:3: expected a Timecode later than the row before's, found \"10:00:00:04.000\" (rows out "
         "of time order)"},
        {"TruncatedLastRow",
         [] {
             std::string t = openface_two_rows();
             return t.substr(0, t.size() - 40);
         },
         "capture: take.csv:3: expected 31 comma-separated fields, as the header on line 1 has, found 24"},
        {"NoRows",
         [] {
             const std::string t = live_link_csv({});
             return t;
         },
         "capture: take.csv:2: expected rows of data after the header, found none"},
        {"EmptyFile", [] { return std::string(""); },
         "fap: take.csv:1: expected a header line `version name fps count`, found end of file"},
        {"AnotherCsv", [] { return std::string("x,y,z\n1,2,3\n"); },
         "capture: take.csv:1: expected a FAP file, or a CSV whose header is OpenFace 2.0's (timestamp, success, "
         "confidence, AU01_r ...), Live Link Face's (Timecode, BlendShapeCount, EyeBlinkLeft ...) or MediaPipe "
         "blendshapes' (timestamp_ms or frame, eyeBlinkLeft ...), found the header \"x,y,z\""},
        {"AnObjFile", [] { return std::string("# a mesh\nv 0 0 0\nv 1 0 0\n"); },
         "fap: take.csv:2: expected a header `version name fps count`, found 'v 0 0 0'"},
        {"AuOutOfRange",
         [] {
             OpenFaceRow a;
             a.aus = {{12, 7.5}};
             return openface_csv({a});
         },
         "capture: take.csv:2: expected an intensity 0..5 in column AU12_r, found 7.5"},
        {"CoefficientOutOfRange",
         [] { return live_link_csv({{timecode(0), {{"JawOpen", 1.5}}, {}}}); },
         "capture: take.csv:2: expected a coefficient 0..1 in column JawOpen, found 1.5"},
        {"BadTimecode",
         [] { return live_link_csv({{"10:00:61:00.000", {}, {}}}); },
         "capture: take.csv:2: expected a Timecode HH:MM:SS:FF or HH:MM:SS:FF.fff, found \"10:00:61:00.000\""},
        {"NoColumnMovesTheFace",  // found by the fuzzer: frames without FAPs did not survive a FAP round trip
         [] { return std::string("frame, face_id, timestamp, confidence, success, AU03_r\n1, 0, 0.000, 0.98, 1, 1.0\n"); },
         "capture: take.csv:1: expected a column that moves the face (an AU, shape, pose or gaze column the tables "
         "know), found none"},
        {"NoFaceTracked",
         [] {
             OpenFaceRow a;
             a.success = 0;
             return openface_csv({a});
         },
         "capture: take.csv:2: expected at least one row with success 1 and confidence >= 0.5, found none (no face "
         "was tracked)"},
    };
    return table;
}

class MalformedCapture : public ::testing::TestWithParam<Bad> {};

TEST_P(MalformedCapture, OneLineNamingFileLineAndProblem) {
    const Bad& b = GetParam();
    const std::string text = b.text();
    expect_error<InputError>([&] { parse(text); }, b.message);
}

INSTANTIATE_TEST_SUITE_P(Table, MalformedCapture, ::testing::ValuesIn(bad_inputs()),
                         [](const ::testing::TestParamInfo<Bad>& i) { return std::string(i.param.name); });

// --- round trips ----------------------------------------------------------------

std::vector<ex::CaptureFrame> frames_of(const fap::FapStream& s) { return ex::capture_frames(s, emotions(), visemes()); }

double max_fap_difference(const fap::FapStream& a, const fap::FapStream& b) {
    const fap::FapStream ra = fap::resolve_untransmitted(a), rb = fap::resolve_untransmitted(b);
    EXPECT_EQ(ra.frames.size(), rb.frames.size());
    double worst = 0;
    for (std::size_t k = 0; k < std::min(ra.frames.size(), rb.frames.size()); ++k)
        for (int n = 3; n <= fap::kFapCount; ++n) {
            const double x = ra.frames[k].has(n) ? ra.frames[k].get(n) : 0.0;
            const double y = rb.frames[k].has(n) ? rb.frames[k].get(n) : 0.0;
            if (std::abs(x - y) > worst) {
                worst = std::abs(x - y);
                if (worst > 0.5) ADD_FAILURE() << "frame " << k << " FAP " << n << ": " << x << " vs " << y;
            }
        }
    return worst;
}

TEST(CaptureRoundTrip, OpenFaceToFapAndBack) {
    // The AUs OpenFace scores and the AU layer reads back (AU14 is not
    // inferred: on the FAPs it is other mouth AUs).
    std::vector<OpenFaceRow> rows;
    for (int i = 0; i < 10; ++i) {
        OpenFaceRow r;
        r.time = i / 30.0;
        r.aus = {{1, 0.4 * i}, {2, 0.3 * i}, {4, 0.0}, {6, 0.2 * i}, {12, 0.5 * i}, {26, 0.25 * i}, {45, i == 5 ? 5 : 0}};
        r.rx = 0.01 * i, r.ry = -0.02 * i, r.rz = 0.005 * i, r.gx = 0.03 * i, r.gy = -0.01 * i;
        rows.push_back(r);
    }
    const fap::FapStream once = parse(openface_csv(rows));
    // Through the FAP file (what Xface and Greta get), then out as OpenFace.
    const fap::FapStream via_fap = fap::parse_fap(fap::format_fap(once), "take.fap");
    const std::string csv = ex::format_openface_csv(frames_of(via_fap), via_fap.fps);
    const fap::FapStream twice = parse(csv);
    EXPECT_DOUBLE_EQ(twice.fps, 30);
    // Tolerance: 0.1 FAPU (the CSV's 4 decimals on 0..5 and 6 on radians).
    EXPECT_LT(max_fap_difference(once, twice), 0.1);
    // The AU columns themselves, within 0.05 on OpenFace's 0..5 scale.
    const std::vector<ex::CaptureFrame> f = frames_of(twice);
    for (std::size_t k = 0; k < rows.size(); ++k)
        for (const auto& [au, v] : rows[k].aus) EXPECT_NEAR(5 * f[k].aus.mean(au == 45 ? 43 : au), v, 0.05) << "AU" << au << " frame " << k;
}

TEST(CaptureRoundTrip, LiveLinkToFapToArkitToFap) {
    std::vector<ArkitRow> rows;
    for (int i = 0; i < 40; ++i) {
        const double x = i / 39.0;
        rows.push_back({timecode(i),
                        {{"MouthSmileLeft", x}, {"MouthSmileRight", 0.5 * x}, {"BrowDownLeft", 1 - x},
                         {"BrowDownRight", 1 - x}, {"JawOpen", 0.3}, {"EyeBlinkLeft", x > 0.5 ? 1.0 : 0.0},
                         {"CheekPuff", 0.2}, {"JawLeft", 0.4 * x}, {"MouthRollLower", 0.3}},
                        {{"HeadYaw", 0.2 * x}, {"HeadPitch", -0.1}, {"HeadRoll", 0.05}, {"LeftEyeYaw", 0.1},
                         {"RightEyePitch", -0.05}}});
    }
    const fap::FapStream once = parse(live_link_csv(rows));
    EXPECT_DOUBLE_EQ(once.fps, 30);
    const fap::FapStream via_fap = fap::parse_fap(fap::format_fap(once), "take.fap");
    const std::string csv = ex::format_arkit_csv(frames_of(via_fap), via_fap.fps, tables().arkit);
    const fap::FapStream twice = parse(csv);
    // Tolerance: 0.5 FAPU, about 0.03 mm of lip on the default face (the
    // shapes' 6 decimals and the fit's convergence).
    EXPECT_LT(max_fap_difference(once, twice), 0.5);
}

TEST(CaptureRoundTrip, FapToArkitToFapKeepsWhatTheShapesCanShow) {
    // A FAP stream made of AUs the shapes carry, plus head and eye angles.
    fap::FapStream s;
    s.name = "made";
    s.fps = 25;
    for (int k = 0; k < 6; ++k) {
        fap::FapFrame f;
        f.number = k;
        const ex::FapValues v = au_faps({{"AU12L", 0.15 * k}, {"AU4", 0.5}, {"AU26", 0.1 * k}, {"AU25", 0.05 * k}});
        for (int n = 3; n <= fap::kFapCount; ++n)
            if (v[n - 1] != 0) f.set(n, v[n - 1]);
        f.set(49, 1000.0 * k);
        f.set(23, -2000);
        f.set(24, -2000);
        s.frames.push_back(f);
    }
    const std::string csv = ex::format_arkit_csv(frames_of(s), s.fps, tables().arkit);
    const fap::FapStream back = parse(csv);
    EXPECT_DOUBLE_EQ(back.fps, 25);
    EXPECT_LT(max_fap_difference(s, back), 0.5);
}

TEST(CaptureRoundTrip, ExpressionFramesBecomeTheirAus) {
    // A FAP file that drives the face by FAP 2 alone converts to its AUs.
    fap::FapStream s;
    s.fps = 25;
    fap::FapFrame f;
    f.set_expression({1, 63, 0, 0, 0, 0});  // joy at full intensity
    s.frames.push_back(f);
    const std::string csv = ex::format_openface_csv(frames_of(s), s.fps);
    const std::vector<ex::CaptureFrame> back = frames_of(parse(csv));
    const ex::AuIntensities& joy = emotions().prototypes[ex::emotion_index(ex::Emotion::Joy)];
    EXPECT_NEAR(back[0].aus.mean(12), joy.mean(12), 0.02);
    EXPECT_NEAR(back[0].aus.mean(6), joy.mean(6), 0.02);
}

}  // namespace
