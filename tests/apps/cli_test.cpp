// The drawing commands end to end: the built `emoface` binary on good input
// (the file it names exists, decodes, has the right size and frame count),
// on bad input (exit 2, one line naming the problem, no output file left),
// without a display (exit 3), and play's --frames slices joined against the
// whole render. Small sizes keep the suite fast on 2 cores with llvmpipe.
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/videoio.hpp>

#include "emoface/fap/fap_io.h"
#include "emoface/morph/morph.h"
#include "emoface/render/image_diff.h"
#include "emoface/render/image_io.h"
#include "support/run_emoface.h"
#include "support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using emoface::render::ImageRGBA8;

using emoface::testing::args_with;
using emoface::testing::CommandResult;
using emoface::testing::read_file;
using emoface::testing::run_emoface;
using emoface::testing::RunOptions;
using emoface::testing::without_display;
using Args = std::vector<std::string>;

const std::string kData = EMOFACE_DATA_DIR;
const std::string kTour = kData + "/fap/tour.fap";  // 50 frames at 25 frames/s
// Every picture small, the wrinkle maps at their smallest, the face coarser
// and its base colour small: the suite checks behaviour, not looks.
const Args kFast = {"--wrinkle-size", "256", "--samples", "1", "--face-resolution", "0.5", "--texture-size", "256"};
const Args kSmall = args_with({"--size", "160x120"}, kFast);

class AppsCli : public ::testing::Test {
protected:
    void SetUp() override { fs::create_directories(out_dir()); }

    fs::path out_dir() const { return scratch_.dir() / "out"; }
    std::string path(const std::string& name) const { return (out_dir() / name).string(); }
    std::vector<std::string> outputs() const {
        std::vector<std::string> names;
        for (const auto& e : fs::directory_iterator(out_dir())) names.push_back(e.path().filename().string());
        std::sort(names.begin(), names.end());
        return names;
    }

    emoface::testing::ScratchDir scratch_;
};

// Frames a video holds, read back one by one (the container's count can be
// an estimate); sets width and height from the first.
int count_video_frames(const std::string& file, int& width, int& height) {
    cv::VideoCapture cap(file);
    if (!cap.isOpened()) return -1;
    cv::Mat frame;
    int n = 0;
    while (cap.read(frame)) {
        if (n == 0) width = frame.cols, height = frame.rows;
        ++n;
    }
    return n;
}

// The video play wrote: out.mp4, or out.avi where OpenCV has no H.264.
std::string written_video(const std::string& mp4) {
    if (fs::exists(mp4)) return mp4;
    return fs::path(mp4).replace_extension(".avi").string();
}

TEST_F(AppsCli, HelpListsTheCommands) {
    const CommandResult r = run_emoface({"--help"});
    EXPECT_EQ(r.exit_code, 0);
    for (const char* sub : {"play", "mix", "inspect", "morph"}) {
        EXPECT_NE(r.out.find(sub), std::string::npos) << sub << " missing from\n" << r.out;
        const CommandResult h = run_emoface({sub, "--help"});
        EXPECT_EQ(h.exit_code, 0) << sub;
        EXPECT_NE(h.out.find("--out"), std::string::npos) << sub << " --help:\n" << h.out;
    }
}

TEST_F(AppsCli, PlayWritesAVideoWithEveryFrame) {
    const CommandResult r = run_emoface(args_with({"play", kTour, "--out", path("tour.mp4"), "--fps", "10"}, kSmall));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string video = written_video(path("tour.mp4"));
    ASSERT_TRUE(fs::exists(video)) << r.out;
    EXPECT_NE(r.out.find("play: wrote " + video), std::string::npos) << r.out;
    EXPECT_NE(r.out.find(fs::path(video).extension() == ".mp4" ? "H.264 MP4" : "Motion-JPEG AVI"),
              std::string::npos)
        << r.out;
    int w = 0, h = 0;
    // 2 s resampled at 10 frames/s.
    EXPECT_EQ(count_video_frames(video, w, h), 20);
    EXPECT_EQ(w, 160);
    EXPECT_EQ(h, 120);
    // The stage timings are reported.
    EXPECT_NE(r.out.find("per frame"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("morph"), std::string::npos);
    // Only the video: no temporary left beside it.
    EXPECT_EQ(outputs(), std::vector<std::string>{fs::path(video).filename().string()});
}

// --frames A:B with B exclusive: 0:4 and 4:10 into one folder equal 0:10
// (the whole) in another, byte for byte, and are numbered by frame.
TEST_F(AppsCli, PlaySlicesJoinedEqualTheWholeRender) {
    fs::create_directories(out_dir() / "whole");
    fs::create_directories(out_dir() / "parts");
    const Args common = args_with({"--fps", "5"}, kSmall);
    CommandResult r = run_emoface(args_with({"play", kTour, "--out", path("whole/%03d.png")}, common));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = run_emoface(args_with({"play", kTour, "--out", path("parts/%03d.png"), "--frames", "4:"}, common));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("frames 4..9 of 10"), std::string::npos) << r.out;
    r = run_emoface(args_with({"play", kTour, "--out", path("parts/%03d.png"), "--frames", "0:4"}, common));
    ASSERT_EQ(r.exit_code, 0) << r.err;

    std::vector<std::string> whole, parts;
    for (const auto& e : fs::directory_iterator(out_dir() / "whole")) whole.push_back(e.path().filename());
    for (const auto& e : fs::directory_iterator(out_dir() / "parts")) parts.push_back(e.path().filename());
    std::sort(whole.begin(), whole.end());
    std::sort(parts.begin(), parts.end());
    ASSERT_EQ(whole.size(), 10u);
    EXPECT_EQ(whole.front(), "000.png");
    EXPECT_EQ(whole.back(), "009.png");
    ASSERT_EQ(parts, whole);
    for (const auto& name : whole)
        EXPECT_TRUE(read_file(out_dir() / "whole" / name) == read_file(out_dir() / "parts" / name)) << name;
    // The animation moves: the first and the middle frame differ.
    const ImageRGBA8 first = emoface::render::read_image_rgba8(path("whole/000.png"));
    const ImageRGBA8 mid = emoface::render::read_image_rgba8(path("whole/005.png"));
    ASSERT_EQ(first.width, 160);
    ASSERT_EQ(first.height, 120);
    EXPECT_GT(emoface::render::diff_images(first, mid).mean_diff, 0.2);
}

struct BadInput {
    const char* name;
    Args args;            // after `emoface`; OUT, GARBAGE and ANOBJ begin paths made by the test
    std::string message;  // part of the one line on stderr
};

void PrintTo(const BadInput& c, std::ostream* os) { *os << c.name; }

class AppsCliBadInput : public AppsCli, public ::testing::WithParamInterface<BadInput> {};

TEST_P(AppsCliBadInput, ExitsTwoWithItsMessageAndWritesNothing) {
    const BadInput& c = GetParam();
    const std::pair<std::string, std::string> made[] = {
        {"OUT", out_dir().string()},
        {"GARBAGE", scratch_.write("garbage.fap", "this is not a FAP file\n1 2 3\n")},
        {"ANOBJ", scratch_.write("face.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")},
    };
    Args args = c.args;
    for (std::string& a : args)
        for (const auto& [placeholder, made_path] : made)
            if (a.rfind(placeholder, 0) == 0) a.replace(0, placeholder.size(), made_path);
    const CommandResult r = run_emoface(args);
    EXPECT_EQ(r.exit_code, 2) << c.name << "\nstdout: " << r.out << "\nstderr: " << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.name << "\nstderr: " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_TRUE(outputs().empty()) << c.name;
}

INSTANTIATE_TEST_SUITE_P(
    Table, AppsCliBadInput,
    ::testing::Values(
        BadInput{"PlayNoSuchFile", {"play", "OUT/none.fap", "--out", "OUT/a.mp4"}, "no such file"},
        BadInput{"PlayNotAFapFile", {"play", "GARBAGE", "--out", "OUT/a.mp4"}, "fap: "},
        BadInput{"PlayBadSize", {"play", kTour, "--out", "OUT/a.mp4", "--size", "12x"}, "--size '12x'"},
        BadInput{"PlayOddVideoSize", {"play", kTour, "--out", "OUT/a.mp4", "--size", "161x120"}, "even width"},
        BadInput{"PlaySliceBackwards", {"play", kTour, "--out", "OUT/%03d.png", "--frames", "9:3"}, "--frames '9:3': expected A < B"},
        BadInput{"PlaySlicePastTheEnd", {"play", kTour, "--out", "OUT/%03d.png", "--frames", "0:51"}, "frames 0..49"},
        BadInput{"PlaySliceNotANumber", {"play", kTour, "--out", "OUT/%03d.png", "--frames", "a:3"}, "'a' is not one"},
        BadInput{"PlayStillName", {"play", kTour, "--out", "OUT/a.png"}, "frame pattern"},
        BadInput{"PlayFolderIsAFile", {"play", kTour, "--out", "GARBAGE/a.mp4"}, "is a file, not a folder"},
        BadInput{"PlayBadBackend", {"play", kTour, "--out", "OUT/a.mp4", "--backend", "gpu"}, "--backend 'gpu'"},
        BadInput{"PlayBadFace", {"play", kTour, "--out", "OUT/a.mp4", "--face", "OUT/none.obj"}, "--face"},
        BadInput{"MixUnknownEmotion", {"mix", "0.7 angr", "--out", "OUT/a.png"}, "angr"},
        BadInput{"MixSumOverOne", {"mix", "0.7 anger + 0.6 fear", "--out", "OUT/a.png"}, "emotion mix"},
        BadInput{"MixWeightOverOne", {"mix", "1.5 joy", "--out", "OUT/a.png"}, "emotion mix"},
        BadInput{"MixFolderIsAFile", {"mix", "anger", "--out", "GARBAGE/a.png"}, "is a file, not a folder"},
        BadInput{"InspectFrameOutOfRange", {"inspect", kTour, "--frame", "50", "--out", "OUT/a.png"}, "frames 0..49"},
        BadInput{"InspectFapAndMix", {"inspect", kTour, "--mix", "anger", "--out", "OUT/a.png"}, "not both"},
        BadInput{"InspectBadMix", {"inspect", "--mix", "anger + joy", "--out", "OUT/a.png"}, "emotion mix"},
        BadInput{"MorphUnknownExpression", {"morph", "--from", "angry", "--to", "surprise", "--out", "OUT/a.png"}, "--from 'angry'"},
        BadInput{"MorphSameExpression", {"morph", "--from", "fear", "--to", "fear", "--out", "OUT/a.png"}, "both 'fear'"},
        BadInput{"MorphOneStep", {"morph", "--steps", "1", "--out", "OUT/a.png"}, "--steps 1"},
        BadInput{"MorphNoOut", {"morph", "--from", "anger", "--to", "surprise"}, "--out"},
        BadInput{"MixBadWrinkleSize", {"mix", "anger", "--out", "OUT/a.png", "--wrinkle-size", "100"}, "--wrinkle-size 100"},
        BadInput{"PlayObjWithoutFdp", {"play", kTour, "--out", "OUT/a.mp4", "--face", "ANOBJ"}, "--fdp"}),
    [](const ::testing::TestParamInfo<BadInput>& info) { return std::string(info.param.name); });

TEST_F(AppsCli, WindowsWithoutADisplayExitThreeNamingTheFix) {
    for (const Args& args : {Args{"play", kTour}, Args{"inspect", "--mix", "anger"}, Args{"mix", "anger"}}) {
        const CommandResult r = run_emoface(args, without_display());
        EXPECT_EQ(r.exit_code, 3) << args[0] << "\n" << r.err;
        EXPECT_NE(r.err.find("no display"), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("--out"), std::string::npos) << r.err;
        EXPECT_TRUE(outputs().empty());
    }
}

TEST_F(AppsCli, CudaBackendWithoutAGpuExitsThree) {
    if (emoface::morph::cuda_available()) GTEST_SKIP() << "a CUDA device is present";
    const CommandResult r = run_emoface(args_with({"mix", "anger", "--backend", "cuda", "--out", path("a.png")}, kSmall));
    EXPECT_EQ(r.exit_code, 3) << r.err;
    EXPECT_NE(r.err.find("--backend cpu"), std::string::npos) << r.err;
    EXPECT_TRUE(outputs().empty());
}

TEST_F(AppsCli, MixWritesAStillThatShowsTheMix) {
    CommandResult r = run_emoface(args_with({"mix", "0.7 anger + 0.3 fear", "--out", path("mix.png")}, kSmall));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("0.7 anger + 0.3 fear"), std::string::npos) << r.out;
    r = run_emoface(args_with({"mix", "neutral", "--out", path("neutral.png")}, kSmall));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const ImageRGBA8 mix = emoface::render::read_image_rgba8(path("mix.png"));
    const ImageRGBA8 neutral = emoface::render::read_image_rgba8(path("neutral.png"));
    ASSERT_EQ(mix.width, 160);
    ASSERT_EQ(mix.height, 120);
    ASSERT_EQ(neutral.width, 160);
    // The face moved (and wrinkled): not the neutral picture.
    EXPECT_GT(emoface::render::diff_images(mix, neutral).mean_diff, 0.2);
    EXPECT_EQ(outputs(), (std::vector<std::string>{"mix.png", "neutral.png"}));
}

TEST_F(AppsCli, MixSheetHasFiveIntensities) {
    const CommandResult r =
        run_emoface(args_with({"mix", "surprise", "--sheet", "--out", path("sheet.png"), "--size", "96x96"}, kFast));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const ImageRGBA8 sheet = emoface::render::read_image_rgba8(path("sheet.png"));
    // Five 96-pixel tiles side by side with gaps, a title and captions.
    EXPECT_GE(sheet.width, 5 * 96);
    EXPECT_LT(sheet.width, 5 * 96 + 80);
    EXPECT_GT(sheet.height, 96);
    EXPECT_NE(r.out.find("0, 0.25, 0.5, 0.75, 1"), std::string::npos) << r.out;
}

TEST_F(AppsCli, InspectWritesRenderAndMapSideBySide) {
    CommandResult r =
        run_emoface(args_with({"inspect", kTour, "--frame", "30", "--out", path("fap.png"), "--size", "200x160"}, kFast));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("84 feature points"), std::string::npos) << r.out;
    const ImageRGBA8 a = emoface::render::read_image_rgba8(path("fap.png"));
    // Render (200) + gap (6) + map shown at the render's height (160); a 48
    // pixel title band (title, then the frame's AUs).
    EXPECT_EQ(a.width, 200 + 6 + 160);
    EXPECT_EQ(a.height, 160 + 48);

    r = run_emoface(
        args_with({"inspect", "--mix", "0.7 anger + 0.3 fear", "--out", path("mix.png"), "--size", "160x160"}, kFast));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const ImageRGBA8 b = emoface::render::read_image_rgba8(path("mix.png"));
    EXPECT_EQ(b.width, 160 + 6 + 160);
    EXPECT_EQ(b.height, 160 + 48);
}

// The OpenCV window (CTest runs this again under xvfb-run): keys step the
// frame (d +1, D +10) and s saves the picture of the frame shown.
TEST_F(AppsCli, InspectWindowStepsWithKeys) {
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display) GTEST_SKIP() << "no display (apps_inspect_window_under_xvfb runs it under Xvfb)";
    RunOptions in_out;
    in_out.working_dir = out_dir().string();
    const CommandResult r =
        run_emoface(args_with({"inspect", kTour, "--keys", "dDsq", "--size", "160x160"}, kFast), in_out);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(outputs(), std::vector<std::string>{"inspect_11.png"}) << r.out;
    const ImageRGBA8 shot = emoface::render::read_image_rgba8(path("inspect_11.png"));
    EXPECT_EQ(shot.width, 160 + 6 + 160);
    EXPECT_EQ(shot.height, 160 + 48);
}

TEST_F(AppsCli, MorphWritesTheFigureAndTheStageTimes) {
    const CommandResult r =
        run_emoface(
            args_with({"morph", "--from", "anger", "--to", "surprise", "--steps", "3", "--tile", "64", "--out", path("sheet.png")}, kFast));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const ImageRGBA8 sheet = emoface::render::read_image_rgba8(path("sheet.png"));
    // Three 64-pixel columns (with row labels on the left), four rows.
    EXPECT_GT(sheet.width, 3 * 64);
    EXPECT_GT(sheet.height, 4 * 64);
    for (const char* stage : {"[1] allocate", "[2] upload", "[3] kernel", "bump mapping", "[4] free"})
        EXPECT_NE(r.out.find(stage), std::string::npos) << stage << " missing from\n" << r.out;
}

TEST_F(AppsCli, PlaysTheRealXfaceAngerFile) {
    const std::string file = std::string(EMOFACE_REALDATA_DIR) + "/fap/xface_anger.fap";
    if (!fs::exists(file)) GTEST_SKIP() << "real data absent: " << file;
    // Its header says 108 frames (numbered 0..107); every one is rendered.
    const std::size_t frames = emoface::fap::read_fap_file(file).frames.size();
    ASSERT_EQ(frames, 108u);
    const CommandResult r = run_emoface(args_with({"play", file, "--out", path("a.mp4")}, kSmall));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    int w = 0, h = 0;
    EXPECT_EQ(count_video_frames(written_video(path("a.mp4")), w, h), int(frames));
    EXPECT_EQ(w, 160);
    EXPECT_NE(r.out.find(std::to_string(frames) + " frames"), std::string::npos) << r.out;
}

// `emoface wrinkles` writes the seven maps and layouts; the same folder, with
// a map replaced by a "painted" one, drives the pipeline unchanged.
TEST_F(AppsCli, WrinklesWritesKeysThatThePipelineReadsBack) {
    const std::string folder = path("keys");
    CommandResult r = run_emoface({"wrinkles", "--size", "256", "--out", folder});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    // Neutral and one key per wrinkling AU side (wrinkles.json).
    for (const char* key : {"neutral", "AU1L", "AU1R", "AU2L", "AU4R", "AU6L", "AU9L", "AU12R", "AU15L", "AU17"}) {
        const ImageRGBA8 map = emoface::render::read_image_rgba8(folder + "/" + key + ".png");
        EXPECT_EQ(map.width, 256) << key;
        EXPECT_TRUE(fs::exists(folder + "/" + std::string(key) + ".layout.json")) << key;
    }
    r = run_emoface(args_with({"mix", "anger=1", "--wrinkles", folder, "--out", path("generated.png")}, kSmall));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    // The artist flattens anger's glabella key (AU4, both sides): the render
    // loses its anger wrinkles there.
    ImageRGBA8 flat(256, 256);
    for (int i = 0; i < 256 * 256; ++i) {
        flat.pixels[i * 4 + 0] = flat.pixels[i * 4 + 1] = 128;
        flat.pixels[i * 4 + 2] = flat.pixels[i * 4 + 3] = 255;
    }
    emoface::render::write_image(folder + "/AU4L.png", flat);
    emoface::render::write_image(folder + "/AU4R.png", flat);
    r = run_emoface(args_with({"mix", "anger=1", "--wrinkles", folder, "--out", path("painted.png")}, kSmall));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_GT(emoface::render::diff_images(emoface::render::read_image_rgba8(path("generated.png")),
                                           emoface::render::read_image_rgba8(path("painted.png")))
                  .mean_diff,
              0.01);  // renders are deterministic: 0 had the folder been ignored
    // A folder that lacks a map is bad input, and nothing is written.
    fs::remove(folder + "/AU20L.png");
    r = run_emoface(args_with({"mix", "anger=1", "--wrinkles", folder, "--out", path("broken.png")}, kSmall));
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("AU20L.png: missing wrinkle map"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(path("broken.png")));
    r = run_emoface({"wrinkles", "--size", "100", "--out", path("small")});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("wrinkles: --size 100: expected 256..4096"), std::string::npos) << r.err;
}

// --- --side-by-side (mix, play): with the wrinkle maps | without ------------------

// The x range [x0, x0 + width) of `image` as an image of its own.
ImageRGBA8 columns(const ImageRGBA8& image, int x0, int width) {
    ImageRGBA8 out(width, image.height);
    for (int y = 0; y < image.height; ++y)
        std::copy_n(image.at(x0, y), 4 * std::size_t(width), out.pixels.data() + 4 * std::size_t(y) * std::size_t(width));
    return out;
}

// Pixels where any of R, G, B differs by more than `tolerance`.
int differing_pixels(const ImageRGBA8& a, const ImageRGBA8& b, int tolerance) {
    int n = 0;
    for (std::size_t i = 0; i + 3 < a.pixels.size(); i += 4)
        n += std::abs(a.pixels[i] - b.pixels[i]) > tolerance || std::abs(a.pixels[i + 1] - b.pixels[i + 1]) > tolerance ||
             std::abs(a.pixels[i + 2] - b.pixels[i + 2]) > tolerance;
    return n;
}

TEST_F(AppsCli, MixSideBySideIsWithAndWithoutWrinkles) {
    const Args size = args_with({"--size", "240x240"}, kFast);
    CommandResult r = run_emoface(args_with({"mix", "anger", "--side-by-side", "--out", path("both.png")}, size));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("480x240"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("with | without wrinkles"), std::string::npos) << r.out;
    ASSERT_EQ(run_emoface(args_with({"mix", "anger", "--out", path("with.png")}, size)).exit_code, 0);
    ASSERT_EQ(run_emoface(args_with({"mix", "anger", "--no-wrinkles", "--out", path("without.png")}, size)).exit_code, 0);

    const ImageRGBA8 both = emoface::render::read_image_rgba8(path("both.png"));
    ASSERT_EQ(both.width, 480) << "twice as wide as --size";
    ASSERT_EQ(both.height, 240);
    const ImageRGBA8 left = columns(both, 0, 240), right = columns(both, 240, 240);
    // The halves are the two pictures drawn on their own: one pose, one camera.
    const int all = 240 * 240;
    EXPECT_LE(differing_pixels(left, emoface::render::read_image_rgba8(path("with.png")), 4), all / 200);
    EXPECT_LE(differing_pixels(right, emoface::render::read_image_rgba8(path("without.png")), 4), all / 200);
    // They differ where anger's wrinkles shade the skin, and nowhere else:
    // the background (the corner's colour) is the same in both.
    EXPECT_GT(differing_pixels(left, right, 3), 40) << "anger's wrinkles show on the left only";
    const std::uint8_t* bg = right.at(0, 0);
    int background_differing = 0;
    for (int y = 0; y < 240; ++y)
        for (int x = 0; x < 240; ++x) {
            const std::uint8_t *a = left.at(x, y), *b = right.at(x, y);
            const bool differ = std::abs(a[0] - b[0]) > 3 || std::abs(a[1] - b[1]) > 3 || std::abs(a[2] - b[2]) > 3;
            const bool background = std::abs(b[0] - bg[0]) <= 2 && std::abs(b[1] - bg[1]) <= 2 && std::abs(b[2] - bg[2]) <= 2;
            background_differing += differ && background;
        }
    EXPECT_EQ(background_differing, 0);
}

TEST_F(AppsCli, PlaySideBySideFramesAreTwiceAsWide) {
    const CommandResult r =
        run_emoface(args_with({"play", kTour, "--frames", "0:2", "--side-by-side", "--out", path("f%04d.png")}, kSmall));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(outputs(), (std::vector<std::string>{"f0000.png", "f0001.png"}));
    const ImageRGBA8 frame = emoface::render::read_image_rgba8(path("f0001.png"));
    EXPECT_EQ(frame.width, 320);
    EXPECT_EQ(frame.height, 120);
}

TEST_F(AppsCli, SideBySideAndViewerOptionsRejectWhatTheyCannotDo) {
    struct Case {
        Args args;
        std::string message;
    };
    const Case cases[] = {
        {{"mix", "anger", "--side-by-side", "--no-wrinkles", "--out", path("a.png")}, "leave out --no-wrinkles"},
        // Without --out mix opens the viewer, which draws one face.
        {{"mix", "anger", "--side-by-side"}, "--side-by-side is for pictures written with --out"},
        {{"mix", "anger", "--screenshot", path("s.png"), "--out", path("a.png")}, "--screenshot"},
        {{"play", kTour, "--quit-after", "3", "--out", path("a.mp4")}, "--quit-after"},
        // `emoface render` is folded into mix and play: no such command.
        {{"render", "--mix", "anger", "--out", path("a.png")}, "A subcommand is required"},
    };
    for (const Case& c : cases) {
        const CommandResult r = run_emoface(args_with(c.args, kSmall), without_display());
        EXPECT_EQ(r.exit_code, 2) << c.message << "\n" << r.err;
        EXPECT_NE(r.err.find(c.message), std::string::npos) << c.message << "\n" << r.err;
        EXPECT_TRUE(outputs().empty()) << c.message;
    }
}

}  // namespace
