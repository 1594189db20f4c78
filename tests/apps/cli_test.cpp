// The drawing commands end to end: the built `emoface` binary on good input
// (the file it names exists, decodes, has the right size and frame count),
// on bad input (exit 2, one line naming the problem, no output file left),
// without a display (exit 3), and play's --frames slices joined against the
// whole render. Small sizes keep the suite fast on 2 cores with llvmpipe.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/videoio.hpp>

#include "emoface/fap/fap_io.h"
#include "emoface/morph/morph.h"
#include "emoface/render/image_io.h"

namespace {

namespace fs = std::filesystem;
using emoface::render::ImageRGBA8;

struct CommandResult {
    int rc;
    std::string out, err;
};

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

const std::string kData = EMOFACE_DATA_DIR;
const std::string kTour = kData + "/fap/tour.fap";  // 50 frames at 25 frames/s
// Every picture small, the wrinkle maps at their smallest, the face coarser
// and its base colour small: the suite checks behaviour, not looks.
const std::string kFast = " --wrinkle-size 256 --samples 1 --face-resolution 0.5 --texture-size 256";
const std::string kSmall = " --size 160x120" + kFast;

class AppsCli : public ::testing::Test {
protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() /
               ("emoface_apps_cli_" + std::to_string(::getpid()) + "_" + info->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_ / "out");
    }
    void TearDown() override { fs::remove_all(dir_); }

    // Runs `emoface ARGS` (with `env` prefixed, e.g. "env -u DISPLAY").
    CommandResult run(const std::string& args, const std::string& env = "") {
        const fs::path out = dir_ / "stdout", err = dir_ / "stderr";
        // The binary keeps ASan's checks but not LeakSanitizer's: GL drivers,
        // OpenImageIO and OpenCV keep one-time allocations past exit.
        const std::string command = env + (env.empty() ? "" : " ") +
                                    "ASAN_OPTIONS=\"${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0\" '" +
                                    EMOFACE_BINARY + "' " + args + " >'" + out.string() + "' 2>'" + err.string() +
                                    "'";
        const int status = std::system(command.c_str());
        return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
    }

    std::string path(const std::string& name) const { return (dir_ / "out" / name).string(); }
    std::vector<std::string> outputs() const {
        std::vector<std::string> names;
        for (const auto& e : fs::directory_iterator(dir_ / "out")) names.push_back(e.path().filename().string());
        std::sort(names.begin(), names.end());
        return names;
    }
    std::string write(const std::string& name, const std::string& text) {
        const fs::path p = dir_ / name;
        std::ofstream(p, std::ios::binary) << text;
        return p.string();
    }

    fs::path dir_;
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

// Mean absolute difference per channel over two images of one size.
double mean_difference(const ImageRGBA8& a, const ImageRGBA8& b) {
    double sum = 0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i) sum += std::abs(int(a.pixels[i]) - int(b.pixels[i]));
    return sum / double(a.pixels.size());
}

TEST_F(AppsCli, HelpListsTheCommands) {
    const CommandResult r = run("--help");
    EXPECT_EQ(r.rc, 0);
    for (const char* sub : {"play", "mix", "inspect", "morph"}) {
        EXPECT_NE(r.out.find(sub), std::string::npos) << sub << " missing from\n" << r.out;
        const CommandResult h = run(std::string(sub) + " --help");
        EXPECT_EQ(h.rc, 0) << sub;
        EXPECT_NE(h.out.find("--out"), std::string::npos) << sub << " --help:\n" << h.out;
    }
}

TEST_F(AppsCli, PlayWritesAVideoWithEveryFrame) {
    const CommandResult r = run("play '" + kTour + "' --out '" + path("tour.mp4") + "' --fps 10" + kSmall);
    ASSERT_EQ(r.rc, 0) << r.err;
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
    fs::create_directories(dir_ / "out" / "whole");
    fs::create_directories(dir_ / "out" / "parts");
    const std::string common = " --fps 5" + kSmall;
    CommandResult r = run("play '" + kTour + "' --out '" + path("whole/%03d.png") + "'" + common);
    ASSERT_EQ(r.rc, 0) << r.err;
    r = run("play '" + kTour + "' --out '" + path("parts/%03d.png") + "' --frames 4:" + common);
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.out.find("frames 4..9 of 10"), std::string::npos) << r.out;
    r = run("play '" + kTour + "' --out '" + path("parts/%03d.png") + "' --frames 0:4" + common);
    ASSERT_EQ(r.rc, 0) << r.err;

    std::vector<std::string> whole, parts;
    for (const auto& e : fs::directory_iterator(dir_ / "out" / "whole")) whole.push_back(e.path().filename());
    for (const auto& e : fs::directory_iterator(dir_ / "out" / "parts")) parts.push_back(e.path().filename());
    std::sort(whole.begin(), whole.end());
    std::sort(parts.begin(), parts.end());
    ASSERT_EQ(whole.size(), 10u);
    EXPECT_EQ(whole.front(), "000.png");
    EXPECT_EQ(whole.back(), "009.png");
    ASSERT_EQ(parts, whole);
    for (const auto& name : whole)
        EXPECT_TRUE(slurp(dir_ / "out" / "whole" / name) == slurp(dir_ / "out" / "parts" / name)) << name;
    // The animation moves: the first and the middle frame differ.
    const ImageRGBA8 first = emoface::render::read_image_rgba8(path("whole/000.png"));
    const ImageRGBA8 mid = emoface::render::read_image_rgba8(path("whole/005.png"));
    ASSERT_EQ(first.width, 160);
    ASSERT_EQ(first.height, 120);
    EXPECT_GT(mean_difference(first, mid), 0.2);
}

struct BadInput {
    const char* name;
    std::string args;     // after `emoface`; OUT stands for the output folder
    std::string message;  // part of the one line on stderr
};

void PrintTo(const BadInput& c, std::ostream* os) { *os << c.name; }

class AppsCliBadInput : public AppsCli, public ::testing::WithParamInterface<BadInput> {};

TEST_P(AppsCliBadInput, ExitsTwoWithItsMessageAndWritesNothing) {
    const BadInput& c = GetParam();
    std::string args = c.args;
    for (std::size_t at; (at = args.find("OUT")) != std::string::npos;) args.replace(at, 3, (dir_ / "out").string());
    const std::string garbage = write("garbage.fap", "this is not a FAP file\n1 2 3\n");
    for (std::size_t at; (at = args.find("GARBAGE")) != std::string::npos;) args.replace(at, 7, garbage);
    const std::string obj = write("face.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    for (std::size_t at; (at = args.find("ANOBJ")) != std::string::npos;) args.replace(at, 5, obj);
    const CommandResult r = run(args);
    EXPECT_EQ(r.rc, 2) << args << "\nstdout: " << r.out << "\nstderr: " << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << args << "\nstderr: " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_TRUE(outputs().empty()) << args;
}

const std::string kTourArg = " '" + kTour + "'";

INSTANTIATE_TEST_SUITE_P(
    Table, AppsCliBadInput,
    ::testing::Values(
        BadInput{"PlayNoSuchFile", "play OUT/none.fap --out OUT/a.mp4", "no such file"},
        BadInput{"PlayNotAFapFile", "play GARBAGE --out OUT/a.mp4", "fap: "},
        BadInput{"PlayBadSize", "play" + kTourArg + " --out OUT/a.mp4 --size 12x", "--size '12x'"},
        BadInput{"PlayOddVideoSize", "play" + kTourArg + " --out OUT/a.mp4 --size 161x120", "even width"},
        BadInput{"PlaySliceBackwards", "play" + kTourArg + " --out OUT/%03d.png --frames 9:3", "--frames 9:3"},
        BadInput{"PlaySlicePastTheEnd", "play" + kTourArg + " --out OUT/%03d.png --frames 0:51", "frames 0..49"},
        BadInput{"PlaySliceNotANumber", "play" + kTourArg + " --out OUT/%03d.png --frames a:3", "not a frame"},
        BadInput{"PlayStillName", "play" + kTourArg + " --out OUT/a.png", "frame pattern"},
        BadInput{"PlayMissingFolder", "play" + kTourArg + " --out OUT/nope/a.mp4", "does not exist"},
        BadInput{"PlayBadBackend", "play" + kTourArg + " --out OUT/a.mp4 --backend gpu", "--backend 'gpu'"},
        BadInput{"PlayBadFace", "play" + kTourArg + " --out OUT/a.mp4 --face OUT/none.obj", "--face"},
        BadInput{"MixUnknownEmotion", "mix \"0.7 angr\" --out OUT/a.png", "angr"},
        BadInput{"MixSumOverOne", "mix \"0.7 anger + 0.6 fear\" --out OUT/a.png", "emotion mix"},
        BadInput{"MixWeightOverOne", "mix \"1.5 joy\" --out OUT/a.png", "emotion mix"},
        BadInput{"MixMissingFolder", "mix anger --out OUT/nope/a.png", "does not exist"},
        BadInput{"InspectFrameOutOfRange", "inspect" + kTourArg + " --frame 50 --out OUT/a.png", "frames 0..49"},
        BadInput{"InspectFapAndMix", "inspect" + kTourArg + " --mix anger --out OUT/a.png", "not both"},
        BadInput{"InspectBadMix", "inspect --mix \"anger + joy\" --out OUT/a.png", "emotion mix"},
        BadInput{"MorphUnknownExpression", "morph --from angry --to surprise --out OUT/a.png", "--from 'angry'"},
        BadInput{"MorphSameExpression", "morph --from fear --to fear --out OUT/a.png", "both 'fear'"},
        BadInput{"MorphOneStep", "morph --steps 1 --out OUT/a.png", "--steps 1"},
        BadInput{"MorphNoOut", "morph --from anger --to surprise", "--out"},
        BadInput{"MixBadWrinkleSize", "mix anger --out OUT/a.png --wrinkle-size 100", "--wrinkle-size 100"},
        BadInput{"PlayObjWithoutFdp", "play" + kTourArg + " --out OUT/a.mp4 --face ANOBJ", "--fdp"}),
    [](const ::testing::TestParamInfo<BadInput>& info) { return std::string(info.param.name); });

TEST_F(AppsCli, WindowsWithoutADisplayExitThreeNamingTheFix) {
    for (const std::string& args :
         std::vector<std::string>{"play" + kTourArg, "inspect --mix anger", "mix anger"}) {
        const CommandResult r = run(args, "env -u DISPLAY -u WAYLAND_DISPLAY");
        EXPECT_EQ(r.rc, 3) << args << "\n" << r.err;
        EXPECT_NE(r.err.find("no display"), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("--out"), std::string::npos) << r.err;
        EXPECT_TRUE(outputs().empty());
    }
}

TEST_F(AppsCli, CudaBackendWithoutAGpuExitsThree) {
    if (emoface::morph::cuda_available()) GTEST_SKIP() << "a CUDA device is present";
    const CommandResult r = run("mix anger --backend cuda --out '" + path("a.png") + "'" + kSmall);
    EXPECT_EQ(r.rc, 3) << r.err;
    EXPECT_NE(r.err.find("--backend cpu"), std::string::npos) << r.err;
    EXPECT_TRUE(outputs().empty());
}

TEST_F(AppsCli, MixWritesAStillThatShowsTheMix) {
    CommandResult r = run("mix \"0.7 anger + 0.3 fear\" --out '" + path("mix.png") + "'" + kSmall);
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.out.find("0.7 anger + 0.3 fear"), std::string::npos) << r.out;
    r = run("mix neutral --out '" + path("neutral.png") + "'" + kSmall);
    ASSERT_EQ(r.rc, 0) << r.err;
    const ImageRGBA8 mix = emoface::render::read_image_rgba8(path("mix.png"));
    const ImageRGBA8 neutral = emoface::render::read_image_rgba8(path("neutral.png"));
    ASSERT_EQ(mix.width, 160);
    ASSERT_EQ(mix.height, 120);
    ASSERT_EQ(neutral.width, 160);
    // The face moved (and wrinkled): not the neutral picture.
    EXPECT_GT(mean_difference(mix, neutral), 0.2);
    EXPECT_EQ(outputs(), (std::vector<std::string>{"mix.png", "neutral.png"}));
}

TEST_F(AppsCli, MixSheetHasFiveIntensities) {
    const CommandResult r =
        run("mix surprise --sheet --out '" + path("sheet.png") + "' --size 96x96" + kFast);
    ASSERT_EQ(r.rc, 0) << r.err;
    const ImageRGBA8 sheet = emoface::render::read_image_rgba8(path("sheet.png"));
    // Five 96-pixel tiles side by side with gaps, a title and captions.
    EXPECT_GE(sheet.width, 5 * 96);
    EXPECT_LT(sheet.width, 5 * 96 + 80);
    EXPECT_GT(sheet.height, 96);
    EXPECT_NE(r.out.find("0, 0.25, 0.5, 0.75, 1"), std::string::npos) << r.out;
}

TEST_F(AppsCli, InspectWritesRenderAndMapSideBySide) {
    CommandResult r = run("inspect" + kTourArg + " --frame 30 --out '" + path("fap.png") +
                          "' --size 200x160" + kFast);
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.out.find("84 feature points"), std::string::npos) << r.out;
    const ImageRGBA8 a = emoface::render::read_image_rgba8(path("fap.png"));
    // Render (200) + gap (6) + map shown at the render's height (160); a 30
    // pixel title band.
    EXPECT_EQ(a.width, 200 + 6 + 160);
    EXPECT_EQ(a.height, 160 + 30);

    r = run("inspect --mix \"0.7 anger + 0.3 fear\" --out '" + path("mix.png") +
            "' --size 160x160" + kFast);
    ASSERT_EQ(r.rc, 0) << r.err;
    const ImageRGBA8 b = emoface::render::read_image_rgba8(path("mix.png"));
    EXPECT_EQ(b.width, 160 + 6 + 160);
    EXPECT_EQ(b.height, 160 + 30);
}

// The OpenCV window (CTest runs this again under xvfb-run): keys step the
// frame (d +1, D +10) and s saves the picture of the frame shown.
TEST_F(AppsCli, InspectWindowStepsWithKeys) {
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display) GTEST_SKIP() << "no display (apps_inspect_window_under_xvfb runs it under Xvfb)";
    const CommandResult r = run("inspect" + kTourArg + " --keys dDsq --size 160x160" + kFast,
                                "cd '" + (dir_ / "out").string() + "' &&");
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_EQ(outputs(), std::vector<std::string>{"inspect_11.png"}) << r.out;
    const ImageRGBA8 shot = emoface::render::read_image_rgba8(path("inspect_11.png"));
    EXPECT_EQ(shot.width, 160 + 6 + 160);
    EXPECT_EQ(shot.height, 160 + 30);
}

TEST_F(AppsCli, MorphWritesTheFigureAndTheStageTimes) {
    const CommandResult r =
        run("morph --from anger --to surprise --steps 3 --tile 64 --out '" + path("sheet.png") + "'" + kFast);
    ASSERT_EQ(r.rc, 0) << r.err;
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
    const CommandResult r = run("play '" + file + "' --out '" + path("a.mp4") + "'" + kSmall);
    ASSERT_EQ(r.rc, 0) << r.err;
    int w = 0, h = 0;
    EXPECT_EQ(count_video_frames(written_video(path("a.mp4")), w, h), int(frames));
    EXPECT_EQ(w, 160);
    EXPECT_NE(r.out.find(std::to_string(frames) + " frames"), std::string::npos) << r.out;
}

// `emoface wrinkles` writes the seven maps and layouts; the same folder, with
// a map replaced by a "painted" one, drives the pipeline unchanged.
TEST_F(AppsCli, WrinklesWritesKeysThatThePipelineReadsBack) {
    const std::string folder = path("keys");
    CommandResult r = run("wrinkles --size 256 --out '" + folder + "'");
    ASSERT_EQ(r.rc, 0) << r.err;
    for (const char* key : {"neutral", "joy", "sadness", "anger", "fear", "disgust", "surprise"}) {
        const ImageRGBA8 map = emoface::render::read_image_rgba8(folder + "/" + key + ".png");
        EXPECT_EQ(map.width, 256) << key;
        EXPECT_TRUE(fs::exists(folder + "/" + std::string(key) + ".layout.json")) << key;
    }
    r = run("mix \"anger=1\" --wrinkles '" + folder + "' --out '" + path("generated.png") + "'" + kSmall);
    ASSERT_EQ(r.rc, 0) << r.err;
    // The artist flattens the anger map: the render loses its anger wrinkles.
    ImageRGBA8 flat(256, 256);
    for (int i = 0; i < 256 * 256; ++i) {
        flat.pixels[i * 4 + 0] = flat.pixels[i * 4 + 1] = 128;
        flat.pixels[i * 4 + 2] = flat.pixels[i * 4 + 3] = 255;
    }
    emoface::render::write_image(folder + "/anger.png", flat);
    r = run("mix \"anger=1\" --wrinkles '" + folder + "' --out '" + path("painted.png") + "'" + kSmall);
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_GT(mean_difference(emoface::render::read_image_rgba8(path("generated.png")),
                              emoface::render::read_image_rgba8(path("painted.png"))),
              0.01);  // renders are deterministic: 0 had the folder been ignored
    // A folder that lacks a map is bad input, and nothing is written.
    fs::remove(folder + "/fear.png");
    r = run("mix \"anger=1\" --wrinkles '" + folder + "' --out '" + path("broken.png") + "'" + kSmall);
    EXPECT_EQ(r.rc, 2);
    EXPECT_NE(r.err.find("fear.png: missing wrinkle map"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(path("broken.png")));
    r = run("wrinkles --size 100 --out '" + path("small") + "'");
    EXPECT_EQ(r.rc, 2);
    EXPECT_NE(r.err.find("--size must be 256..4096, found 100"), std::string::npos) << r.err;
}

}  // namespace
