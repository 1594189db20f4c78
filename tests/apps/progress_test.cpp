// The progress bar's line: frame, total, frames/s and time left.
#include <gtest/gtest.h>

#include <algorithm>
#include <utility>
#include <vector>

#include "progress.h"

namespace {

using emoface::apps::FrameTimeAverage;
using emoface::apps::ProgressBar;

struct Case {
    int done, total;
    double elapsed, seconds_per_frame;
    const char* line;
};

TEST(ProgressBar, Format) {
    const Case cases[] = {
        {0, 107, 0.0, 0.0, "play [....................]   0/107"},
        {10, 100, 2.0, 0.0, "play [##..................]  10/100"},  // no average yet
        {10, 100, 2.0, 0.2, "play [##..................]  10/100  5.0 frames/s  18 s left"},
        // The time left follows the averaged frame time, not elapsed / done.
        {50, 100, 4.0, 0.1, "play [##########..........]  50/100  10.0 frames/s  5 s left"},
        {1, 1000, 1.0, 1.0, "play [....................]    1/1000  1.0 frames/s  16:39 min left"},
        // Finished: the overall rate and the elapsed time.
        {100, 100, 8.0, 0.1, "play [####################] 100/100  12.5 frames/s  8 s"},
        {150, 100, 8.0, 0.1, "play [####################] 100/100  12.5 frames/s  8 s"},  // clamped
    };
    for (const Case& c : cases)
        EXPECT_EQ(ProgressBar::format("play", c.done, c.total, c.elapsed, c.seconds_per_frame, 20), c.line)
            << c.done << "/" << c.total;
}

struct AverageCase {
    const char* what;
    std::vector<std::pair<double, int>> adds;  // (seconds, frames)
    double expected;
};

TEST(FrameTimeAverage, SmoothsTheFrameTime) {
    const AverageCase cases[] = {
        {"the first frame sets it", {{0.5, 1}}, 0.5},
        {"steady frames keep it", {{0.1, 1}, {0.1, 1}, {0.1, 1}}, 0.1},
        {"a batch is its mean per frame", {{1.0, 4}}, 0.25},
        // One 1.1 s frame after 0.1 s ones moves the mean by alpha (0.1) of the gap only.
        {"one slow frame", {{0.1, 1}, {1.1, 1}}, 0.2},
        // Two frames reported at once weigh as two single reports.
        {"batches weigh per frame", {{0.1, 1}, {0.6, 2}}, 0.1 + (1 - 0.81) * 0.2},
        {"no frames: ignored", {{0.1, 1}, {5.0, 0}}, 0.1},
    };
    for (const AverageCase& c : cases) {
        FrameTimeAverage average(0.1);
        for (auto [seconds, frames] : c.adds) average.add(seconds, frames);
        EXPECT_NEAR(average.seconds_per_frame(), c.expected, 1e-12) << c.what;
    }
    FrameTimeAverage converges(0.1);
    converges.add(0.1, 1);
    for (int i = 0; i < 100; ++i) converges.add(0.3, 1);
    EXPECT_NEAR(converges.seconds_per_frame(), 0.3, 1e-4) << "a lasting change is followed";
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

// The last state is drawn once: finish() after the last update() adds only
// the line end (it used to draw the final line a second time).
TEST(ProgressBar, DrawsTheLastLineOnce) {
    testing::internal::CaptureStderr();
    {
        ProgressBar bar("play", 3, true);
        for (int i = 1; i <= 3; ++i) bar.update(i);
        bar.finish();
    }
    const std::string err = testing::internal::GetCapturedStderr();
    std::size_t count = 0;
    for (auto at = err.find("3/3"); at != std::string::npos; at = err.find("3/3", at + 1)) ++count;
    EXPECT_EQ(count, 1u) << err;
    EXPECT_EQ(err.back(), '\n');
}

}  // namespace
