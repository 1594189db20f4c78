// The progress bar's line: frame, total, frames/s and time left.
#include <gtest/gtest.h>

#include "progress.h"

namespace {

using emoface::apps::ProgressBar;

struct Case {
    int done, total;
    double seconds;
    const char* line;
};

TEST(ProgressBar, Format) {
    const Case cases[] = {
        {0, 107, 0.0, "play [....................]   0/107"},
        {10, 100, 2.0, "play [##..................]  10/100  5.0 frames/s  18 s left"},
        {50, 100, 4.0, "play [##########..........]  50/100  12.5 frames/s  4 s left"},
        {1, 1000, 1.0, "play [....................]    1/1000  1.0 frames/s  16:39 min left"},
        {100, 100, 8.0, "play [####################] 100/100  12.5 frames/s  8 s"},
        {150, 100, 8.0, "play [####################] 100/100  12.5 frames/s  8 s"},  // clamped
    };
    for (const Case& c : cases)
        EXPECT_EQ(ProgressBar::format("play", c.done, c.total, c.seconds, 20), c.line)
            << c.done << "/" << c.total;
}

TEST(ProgressBar, QuietWhenDisabled) {
    testing::internal::CaptureStderr();
    {
        ProgressBar bar("play", 10, false);
        for (int i = 1; i <= 10; ++i) bar.update(i);
        bar.finish();
    }
    EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
}

TEST(ProgressBar, DrawsInPlaceWhenEnabled) {
    testing::internal::CaptureStderr();
    {
        ProgressBar bar("play", 3, true);
        for (int i = 1; i <= 3; ++i) bar.update(i);
        bar.finish();
    }
    const std::string err = testing::internal::GetCapturedStderr();
    EXPECT_EQ(err.front(), '\r');
    EXPECT_NE(err.find("3/3"), std::string::npos) << err;
    EXPECT_EQ(err.back(), '\n');
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
}

}  // namespace
