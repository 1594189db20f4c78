// `emoface info` end to end: the built binary on the bundled sample, bad
// files, several files at once and the real files of other systems.
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/run_emoface.h"
#include "support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using emoface::testing::CommandResult;
using emoface::testing::run_emoface;

class InfoCli : public ::testing::Test {
protected:
    emoface::testing::ScratchDir scratch_;
};

const std::string kTour = std::string(EMOFACE_DATA_DIR) + "/fap/tour.fap";

TEST_F(InfoCli, BundledTour) {
    const CommandResult r = run_emoface({"info", kTour});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err, "");
    EXPECT_NE(r.out.find("  version   2.1\n"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("  name      emoface tour\n"), std::string::npos);
    EXPECT_NE(r.out.find("  frames    50 (numbered 0..49)\n"), std::string::npos);
    EXPECT_NE(r.out.find("  duration  2.000 s\n"), std::string::npos);
    EXPECT_NE(r.out.find("    31 raise_l_i_eyebrow      -120 .. 200\n"), std::string::npos);
    EXPECT_NE(r.out.find("  FAP 1     not used\n"), std::string::npos);
    EXPECT_NE(r.out.find("  moving    22 low-level FAPs, 2 expressions (FAP 2)\n"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("  FAP 2     31 frames, 2 expressions (intensity 0..63; frames counted from 0):\n"
                         "    joy       intensity  0..63  19 frames in 24..49\n"
                         "    anger     intensity  0..63  24 frames in 12..35\n"),
              std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("  warnings  none\n"), std::string::npos);
}

TEST_F(InfoCli, Json) {
    const CommandResult r = run_emoface({"info", "--json", kTour});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    ASSERT_TRUE(j.is_array());
    ASSERT_EQ(j.size(), 1u);
    EXPECT_EQ(j[0]["version"], "2.1");
    EXPECT_EQ(j[0]["frames"], 50);
    EXPECT_EQ(j[0]["fps"], 25.0);
    EXPECT_DOUBLE_EQ(j[0]["duration_s"].get<double>(), 2.0);
    EXPECT_EQ(j[0]["moving_faps"].size(), 22u);
    EXPECT_EQ(j[0]["moving_faps"][0]["name"], "raise_l_cornerlip");
    EXPECT_EQ(j[0]["expression"]["frames"], 31);
    EXPECT_EQ(j[0]["expression"]["expressions"][0]["name"], "joy");
    EXPECT_EQ(j[0]["viseme"]["frames"], 0);
    EXPECT_TRUE(j[0]["warnings"].empty());
}

TEST_F(InfoCli, BadFileIsOneLineAndExitTwo) {
    const std::string bad = scratch_.write("bad.fap", "2.1 anim 25 1\n1 0 0\n");
    const CommandResult r = run_emoface({"info", bad});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.out, "");
    EXPECT_EQ(r.err, "emoface: fap: " + bad +
                         ":2: frame 1: expected a mask of 68 tokens (69 from Greta's Java writer), found 3\n");
    const CommandResult missing = run_emoface({"info", scratch_.path("none.fap")});
    EXPECT_EQ(missing.exit_code, 2);
    EXPECT_EQ(missing.err, "emoface: fap: " + scratch_.path("none.fap") +
                               ": expected a regular file of at most 256 MiB, found no such file\n");
}

TEST_F(InfoCli, SeveralFilesReportEveryGoodOneAndStillFail) {
    const std::string bad1 = scratch_.write("bad1.fap", "junk\n");
    const std::string bad2 = scratch_.write("bad2.fap", "");
    const CommandResult r = run_emoface({"info", bad1, kTour, bad2});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.out.find("  frames    50 (numbered 0..49)\n"), std::string::npos);
    EXPECT_EQ(r.err, "emoface: fap: " + bad1 + ":1: expected a header `version name fps count`, found 'junk'\n" +
                         "emoface: fap: " + bad2 + ":1: expected a header line `version name fps count`, found end of file\n");
    const CommandResult j = run_emoface({"info", "--json", bad1, kTour});
    EXPECT_EQ(j.exit_code, 2);
    const nlohmann::json parsed = nlohmann::json::parse(j.out);
    ASSERT_EQ(parsed.size(), 2u);
    EXPECT_TRUE(parsed[0].contains("error"));
    EXPECT_EQ(parsed[1]["frames"], 50);
}

// The acceptance check of issue 2 on the real files.
TEST_F(InfoCli, RealFiles) {
    const fs::path real = fs::path(EMOFACE_REALDATA_DIR) / "fap";
    if (!fs::is_directory(real)) GTEST_SKIP() << "no real FAP files at " << real;
    std::vector<std::string> args{"info", "--json"};
    for (const auto& e : fs::directory_iterator(real)) args.push_back(e.path().string());
    const CommandResult r = run_emoface(args);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    int xface_emotions = 0;
    for (const auto& f : j) {
        const std::string file = fs::path(f["file"].get<std::string>()).filename().string();
        SCOPED_TRACE(file);
        if (file.rfind("xface_", 0) == 0 && file != "xface_test.fap") {
            ++xface_emotions;
            EXPECT_GE(f["frames"].get<int>(), 107);
            EXPECT_LE(f["frames"].get<int>(), 108);
        }
        if (file == "greta_empty.fap") EXPECT_EQ(f["frames"], 0);
        if (file == "vreng_jag.fap") EXPECT_EQ(f["version"], "2.0");
    }
    EXPECT_EQ(xface_emotions, 8);
}

}  // namespace
