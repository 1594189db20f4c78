// Bad output paths and numeric options (issue 12): each row is an argument
// vector and the exact one line it must print; every row exits 2 within
// 10 s and leaves the folder exactly as it was (no temporaries, no staging
// folder, no partial frames, maps or .mtl, no folder made on the way).
// Paths are relative to the scratch folder the command runs in, so messages
// are the same on every machine. Tests may run as root, where permissions do
// not block: unwritable places are /proc (which refuses new entries to
// everyone) and a file where a folder is expected.
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/run_emoface.h"
#include "support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using emoface::testing::args_with;
using emoface::testing::CommandResult;
using emoface::testing::run_emoface;
using emoface::testing::RunOptions;
using Args = std::vector<std::string>;

const std::string kTour = std::string(EMOFACE_DATA_DIR) + "/fap/tour.fap";  // 50 frames
const Args kSmall = {"--size", "160x120", "--wrinkle-size", "256", "--samples", "1", "--face-resolution", "0.5",
                     "--texture-size", "256"};

struct Row {
    Args args;  // after `emoface`
    std::string line;  // all of stderr, without "emoface: " and the newline
};

// Every path under `dir`, hidden ones included.
std::set<std::string> tree(const fs::path& dir) {
    std::set<std::string> out;
    for (const auto& e : fs::recursive_directory_iterator(dir)) out.insert(fs::relative(e.path(), dir).string());
    return out;
}

class BadOutput : public ::testing::Test {
protected:
    void SetUp() override {
        fs::create_directories(scratch_.dir() / "out" / "blocked" / "f2.png");  // a folder where frame 2 goes
        scratch_.write("out/afile", "a file where a folder is expected\n");
    }

    void expect_rows(const std::vector<Row>& rows) {
        RunOptions options = emoface::testing::without_display();
        options.working_dir = scratch_.dir().string();
        options.timeout_seconds = 10;
        const std::set<std::string> before = tree(scratch_.dir());
        for (const Row& row : rows) {
            std::string what;
            for (const std::string& a : row.args) what += " '" + a + "'";
            const CommandResult r = run_emoface(row.args, options);
            EXPECT_FALSE(r.timed_out) << what;
            EXPECT_EQ(r.exit_code, 2) << what << "\n" << r.err;
            EXPECT_EQ(r.err, "emoface: " + row.line + "\n") << what;
            EXPECT_LE(r.err.size(), 300u) << what;
            EXPECT_EQ(tree(scratch_.dir()), before) << what << ": the folder changed";
        }
    }

    emoface::testing::ScratchDir scratch_;
};

TEST_F(BadOutput, PathsFailBeforeAnyLoadingAndLeaveNothing) {
    const std::string image_names = "expected an image name OpenImageIO writes (.png, .jpg, .tif, .exr, ...), found";
    expect_rows({
        {args_with({"mix", "joy", "--out", "out/a.xyz"}, kSmall), "mix: --out out/a.xyz: " + image_names + " extension '.xyz'"},
        {args_with({"mix", "joy", "--out", "out/a"}, kSmall), "mix: --out out/a: " + image_names + " extension none"},
        {args_with({"mix", "joy", "--out", ""}, kSmall), "mix: --out '': expected a file name, found nothing"},
        {args_with({"mix", "joy", "--out", "out"}, kSmall), "mix: --out out: expected a file name, found a folder"},
        {args_with({"mix", "joy", "--out", "/proc/emoface/f.png"}, kSmall),
         "mix: --out /proc/emoface/f.png: cannot write there: No such file or directory"},
        {args_with({"mix", "joy", "--out", "out/afile/deeper/f.png"}, kSmall),
         "mix: --out out/afile/deeper/f.png: out/afile is a file, not a folder"},
        {args_with({"inspect", "--out", "out/a.xyz"}, kSmall), "inspect: --out out/a.xyz: " + image_names + " extension '.xyz'"},
        {args_with({"inspect", "--out", ""}, kSmall), "inspect: --out '': expected a file name, found nothing"},
        {args_with({"play", kTour, "--out", "out/f%03d.xyz"}, kSmall),
         "play: --out out/f%03d.xyz: " + image_names + " extension '.xyz'"},
        {args_with({"play", kTour, "--out", "out/f%03d/x.png"}, kSmall),
         "render: frame pattern 'out/f%03d/x.png': the %d must be in the file name, not in a folder's"},
        {args_with({"play", kTour, "--out", "out/f%s.png"}, kSmall),
         "render: frame pattern 'out/f%s.png': only %d conversions (like %04d) are allowed, found one at character 6"},
        {args_with({"play", kTour, "--out", "out/f%d%d.png"}, kSmall),
         "render: frame pattern 'out/f%d%d.png': needs exactly one %d (like face_%04d.png), found 2"},
        {args_with({"play", kTour, "--out", "out/v.mov"}, kSmall),
         "play: --out out/v.mov: expected a video (.mp4, .mkv, .webm, .avi) or a frame pattern such as frames/%04d.png"},
        {args_with({"play", kTour, "--out", "/proc/emoface/v.mp4"}, kSmall),
         "play: --out /proc/emoface/v.mp4: cannot write there: No such file or directory"},
        {args_with({"play", kTour, "--out", "/proc/emoface/f%04d.png"}, kSmall),
         "play: --out /proc/emoface/f%04d.png: cannot write there: No such file or directory"},
        {args_with({"play", kTour, "--out", "out/afile/v.mp4"}, kSmall),
         "play: --out out/afile/v.mp4: out/afile is a file, not a folder"},
        // The 3rd of 5 frames cannot be written: nothing is, not even the first two.
        {args_with({"play", kTour, "--frames", "0:5", "--out", "out/blocked/f%d.png"}, kSmall),
         "play: --out out/blocked/f%d.png: frame 2 would be out/blocked/f2.png, which is a folder"},
        {{"wrinkles", "--out", "/proc/emoface-w", "--size", "256"},
         "wrinkles: --out /proc/emoface-w: cannot write there: No such file or directory"},
        {{"face", "--out", "/proc/emoface/f.obj", "--resolution", "0.3"},
         "face: --out /proc/emoface/f.obj: cannot write there: No such file or directory"},
        {{"face", "--out", "out/afile/f.obj", "--resolution", "0.3"},
         "face: --out out/afile/f.obj: out/afile is a file, not a folder"},
        {{"view", "--screenshot", "/proc/emoface/s.png"},
         "view: --screenshot /proc/emoface/s.png: cannot write there: No such file or directory"},
        {{"view", "--screenshot", "out/s.xyz"},
         "view: --screenshot out/s.xyz: " + image_names + " extension '.xyz'"},
    });
}

TEST_F(BadOutput, NumbersOutOfRangeOrMalformedExitTwo) {
    const std::string fps = " frames per second";
    const std::string size = "': expected WIDTHxHEIGHT, each 16..8192 (e.g. 1280x720)";
    std::vector<Row> rows;
    for (const auto& [text, shown] : std::vector<std::pair<std::string, std::string>>{
             {"nan", "nan"}, {"0", "0"}, {"inf", "inf"}, {"0.00001", "1e-05"}, {"-25", "-25"}, {"1e9", "1000000000"}})
        rows.push_back({args_with({"play", kTour, "--fps", text, "--out", "out/v.mp4"}, kSmall),
                        "play: --fps " + shown + ": expected 0.1..1000" + fps});
    for (const std::string text : {"4294967360x64", "", "0x0", "-64x64", "99999x64", "64x64x", " 64x64", "64x",
                                   "0x64", "64X15"})
        rows.push_back({{"mix", "joy", "--size", text, "--out", "out/a.png"}, "mix: --size '" + text + size});
    const std::vector<Row> more = {
        {args_with({"play", kTour, "--frames", "", "--out", "out/f%d.png"}, kSmall),
         "play: --frames '': expected A:B (first frame, end frame exclusive), e.g. 0:50, 50: or :50"},
        {args_with({"play", kTour, "--frames", "1:2:3", "--out", "out/f%d.png"}, kSmall),
         "play: --frames '1:2:3': expected A:B (first frame, end frame exclusive), e.g. 0:50, 50: or :50"},
        {args_with({"play", kTour, "--frames", "-1:3", "--out", "out/f%d.png"}, kSmall),
         "play: --frames '-1:3': expected A:B of frame numbers, '-1' is not one"},
        {args_with({"play", kTour, "--frames", "3:3", "--out", "out/f%d.png"}, kSmall),
         "play: --frames '3:3': expected A < B (the end frame B is exclusive)"},
        {args_with({"play", kTour, "--frames", "99999999999:", "--out", "out/f%d.png"}, kSmall),
         "play: --frames '99999999999:': expected A:B of frame numbers, '99999999999' is not one"},
        // Without --out play opens the viewer, which plays the whole file at its rate.
        {{"play", kTour, "--fps", "10"},
         "play: --fps shapes the animation written with --out; the viewer plays the whole file at its own rate "
         "(its timeline scrubs and sets the pace)"},
        {{"play", kTour, "--frames", "0:3"},
         "play: --frames shapes the animation written with --out; the viewer plays the whole file at its own rate "
         "(its timeline scrubs and sets the pace)"},
        {{"mix", "joy", "--face-resolution", "nan", "--out", "out/a.png"}, "mix: --face-resolution nan: expected 0.1..2"},
        {{"mix", "joy", "--face-resolution", "1e400", "--out", "out/a.png"}, "mix: --face-resolution inf: expected 0.1..2"},
        {{"mix", "joy", "--face-resolution", "0.05", "--out", "out/a.png"}, "mix: --face-resolution 0.05: expected 0.1..2"},
        {{"mix", "joy", "--texture-size", "5", "--out", "out/a.png"},
         "mix: --texture-size 5: expected 64..8192 (0: face.json's)"},
        {{"mix", "joy", "--wrinkle-size", "4294967808", "--out", "out/a.png"},
         "mix: Could not convert: --wrinkle-size = 4294967808 (see emoface mix --help)"},
        {{"mix", "joy", "--samples", "99", "--out", "out/a.png"},
         "mix: --samples: Value 99 not in range 1 to 16 (see emoface mix --help)"},
        {{"face", "--out", "out/f.obj", "--resolution", "nan"}, "face: --resolution nan: expected 0.1..2"},
        {{"face", "--out", "out/f.obj", "--texture-size", "10"},
         "face: --texture-size 10: expected 64..8192 (0: face.json's)"},
        {{"view", "--size", "4294967360x720"}, "view: --size '4294967360x720" + size},
    };
    rows.insert(rows.end(), more.begin(), more.end());
    expect_rows(rows);
}

}  // namespace
