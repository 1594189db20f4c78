// FAP values beyond the face's range (issue 12): `play` clamps them, says so
// in one warning line naming the FAPs and frames, and still writes every
// frame; --no-clamp plays them raw without a word.
#include <algorithm>
#include <filesystem>
#include <fstream>
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
using Args = std::vector<std::string>;

const Args kFast = {"--size",    "96x72", "--wrinkle-size",    "256", "--samples",
                    "1",         "--face-resolution", "0.5", "--texture-size", "256"};

// The lines of `text` that start with "emoface: " (the warnings; the
// progress bar writes no newline-ended lines when stderr is not a terminal).
std::vector<std::string> warning_lines(const std::string& text) {
    std::vector<std::string> out;
    std::size_t start = 0;
    while (start < text.size()) {
        std::size_t end = text.find('\n', start);
        if (end == std::string::npos) end = text.size();
        const std::string line = text.substr(start, end - start);
        if (line.rfind("emoface: ", 0) == 0) out.push_back(line);
        start = end + 1;
    }
    return out;
}

// Three frames transmitting raise_b_midlip (FAP 5; the face's range is
// -300..400): frame 1 at -5000, far past what a lip can do.
void write_impossible_fap(const fs::path& file) {
    std::string mask;
    for (int f = 1; f <= 68; ++f) mask += std::string(f == 1 ? "" : " ") + (f == 5 ? "1" : "0");
    std::ofstream out(file);
    out << "2.1 clamp_test 25 3\n";
    const int values[] = {0, -5000, 100};
    for (int k = 0; k < 3; ++k) out << mask << "\n" << k << " " << values[k] << "\n";
}

class PlayClamp : public ::testing::Test {
protected:
    void SetUp() override {
        fs::create_directories(scratch_.dir() / "out");
        write_impossible_fap(fap());
    }
    fs::path fap() const { return scratch_.dir() / "impossible.fap"; }
    std::string pattern() const { return (scratch_.dir() / "out" / "f%02d.png").string(); }
    std::size_t frames_written() const {
        const auto it = fs::directory_iterator(scratch_.dir() / "out");
        return std::size_t(std::distance(fs::begin(it), fs::end(it)));
    }
    emoface::testing::ScratchDir scratch_;
};

TEST_F(PlayClamp, WarnsOnceNamingTheFapAndFrameAndStillWritesEveryFrame) {
    const CommandResult r = run_emoface(args_with({"play", fap().string(), "--out", pattern()}, kFast));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(frames_written(), 3u);
    const auto lines = warning_lines(r.err);
    ASSERT_EQ(lines.size(), 1u) << r.err;
    EXPECT_EQ(lines[0],
              "emoface: play: impossible.fap: 1 FAP value beyond the face's range clamped (raise_b_midlip in "
              "frame 1); --no-clamp keeps them");
}

TEST_F(PlayClamp, NoClampPlaysRawWithoutAWarning) {
    const CommandResult r =
        run_emoface(args_with({"play", fap().string(), "--out", pattern(), "--no-clamp"}, kFast));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(frames_written(), 3u);
    EXPECT_TRUE(warning_lines(r.err).empty()) << r.err;
}

// The file that tore the lower lip: its warning names the lip and the jaw,
// within one line of at most 300 characters.
TEST(PlayClampRealData, VrengJagNamesTheLowerLipAndTheJaw) {
    const std::string file = std::string(EMOFACE_REALDATA_DIR) + "/fap/vreng_jag.fap";
    if (!fs::exists(file)) GTEST_SKIP() << "real data absent: " << file;
    // info says what play would clamp, without rendering.
    const CommandResult r = run_emoface({"info", file});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto lines = warning_lines(r.err);
    ASSERT_EQ(lines.size(), 1u) << r.err;
    EXPECT_LE(lines[0].size(), 300u) << lines[0];
    EXPECT_EQ(lines[0].rfind("emoface: info: vreng_jag.fap: ", 0), 0u) << lines[0];
    EXPECT_NE(lines[0].find("raise_b_midlip in frames"), std::string::npos) << lines[0];
    EXPECT_NE(lines[0].find("thrust_jaw in frames"), std::string::npos) << lines[0];
    EXPECT_NE(lines[0].find("; --no-clamp keeps them"), std::string::npos) << lines[0];
}

}  // namespace
