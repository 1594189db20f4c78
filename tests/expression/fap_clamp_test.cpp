// summarize_clamping / describe_clamping: which values of a FAP stream the
// rig will clamp to the face's ranges, and the one line that says so.
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "emoface/expression/fap_clamp.h"

namespace {

using namespace emoface;
using expression::ClampSummary;
using Runs = std::vector<std::pair<std::size_t, std::size_t>>;

int fap_number(const std::string& name) { return *fap::find_fap(name); }

// open_jaw 0..1000, raise_b_midlip -300..200, thrust_jaw -100..100; the rest unbounded.
expression::FapRanges test_ranges() {
    expression::FapRanges r;
    auto set = [&](const char* name, double lo, double hi) {
        r.lower[std::size_t(fap_number(name) - 1)] = lo;
        r.upper[std::size_t(fap_number(name) - 1)] = hi;
    };
    set("open_jaw", 0, 1000);
    set("raise_b_midlip", -300, 200);
    set("thrust_jaw", -100, 100);
    return r;
}

// One frame per entry: the FAPs it transmits as {name, value}.
using Frame = std::vector<std::pair<std::string, double>>;
fap::FapStream stream_of(const std::vector<Frame>& frames) {
    fap::FapStream s;
    for (std::size_t k = 0; k < frames.size(); ++k) {
        fap::FapFrame f;
        f.number = static_cast<long long>(k);
        for (const auto& [name, value] : frames[k]) {
            const int n = fap_number(name);
            f.values[std::size_t(n - 1)] = value;
            f.mask.set(std::size_t(n - 1));
        }
        s.frames.push_back(f);
    }
    return s;
}

struct Expected {
    const char* fap;
    std::size_t values;
    Runs runs;
};

struct Case {
    const char* name;
    std::vector<Frame> frames;
    std::size_t values;
    std::vector<Expected> faps;  // in the summary's order
    const char* text;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

class FapClamp : public ::testing::TestWithParam<Case> {};

TEST_P(FapClamp, CountsTheValuesBeyondTheRangesAndSaysWhere) {
    const Case& c = GetParam();
    const ClampSummary s = expression::summarize_clamping(stream_of(c.frames), test_ranges());
    EXPECT_EQ(s.values, c.values);
    ASSERT_EQ(s.faps.size(), c.faps.size());
    for (std::size_t i = 0; i < c.faps.size(); ++i) {
        EXPECT_EQ(s.faps[i].fap, fap_number(c.faps[i].fap)) << i;
        EXPECT_EQ(s.faps[i].values, c.faps[i].values) << c.faps[i].fap;
        EXPECT_EQ(s.faps[i].runs, c.faps[i].runs) << c.faps[i].fap;
    }
    EXPECT_EQ(expression::describe_clamping(s), c.text);
}

INSTANTIATE_TEST_SUITE_P(
    Streams, FapClamp,
    ::testing::Values(
        Case{"inside_and_at_the_limits",
             {{{"open_jaw", 1000}, {"raise_b_midlip", -300}}, {{"thrust_jaw", 100}}, {{"squeeze_l_eyebrow", 5000}}},
             0, {}, ""},
        Case{"beyond_max_in_one_frame",
             {{{"raise_b_midlip", 10}}, {{"raise_b_midlip", 250}}, {{"raise_b_midlip", 0}}},
             1, {{"raise_b_midlip", 1, {{1, 1}}}},
             "1 FAP value beyond the face's range clamped (raise_b_midlip in frame 1)"},
        Case{"beyond_min_held_while_untransmitted",
             // Transmitted once at -500: the rig is given it until frame 3 says otherwise.
             {{{"open_jaw", 100}}, {{"thrust_jaw", -500}}, {}, {{"thrust_jaw", 0}}},
             2, {{"thrust_jaw", 2, {{1, 2}}}},
             "2 FAP values beyond the face's range clamped (thrust_jaw in frames 1-2)"},
        Case{"open_jaw_below_zero",
             {{{"open_jaw", -1}}},
             1, {{"open_jaw", 1, {{0, 0}}}},
             "1 FAP value beyond the face's range clamped (open_jaw in frame 0)"},
        Case{"several_faps_and_runs_most_first",
             {{{"thrust_jaw", 200}},
              {{"thrust_jaw", 200}, {"raise_b_midlip", -400}},
              {{"thrust_jaw", 0}, {"raise_b_midlip", 0}},
              {{"thrust_jaw", 200}},
              {{"thrust_jaw", 0}},
              {{"thrust_jaw", -200}},
              {{"thrust_jaw", 0}},
              {{"thrust_jaw", 101}, {"open_jaw", 2000}}},
             7, {{"thrust_jaw", 5, {{0, 1}, {3, 3}, {5, 5}, {7, 7}}}, {"open_jaw", 1, {{7, 7}}}, {"raise_b_midlip", 1, {{1, 1}}}},
             // Ties in FAP order.
             "7 FAP values beyond the face's range clamped (thrust_jaw in frames 0-1, 3 etc., open_jaw in frame 7, "
             "raise_b_midlip in frame 1)"}),
    [](const ::testing::TestParamInfo<Case>& i) { return std::string(i.param.name); });

// Many FAPs: the text keeps to its length and says how many were left out.
TEST(FapClampText, LeavesOutWhatDoesNotFit) {
    expression::FapRanges ranges;
    Frame frame;
    for (int f = 3; f <= fap::kFapCount; ++f) {
        ranges.lower[std::size_t(f - 1)] = -1;
        ranges.upper[std::size_t(f - 1)] = 1;
        frame.emplace_back(std::string(fap::fap_info(f).name), 2.0);
    }
    const ClampSummary s = expression::summarize_clamping(stream_of({frame}), ranges);
    EXPECT_EQ(s.values, std::size_t(fap::kFapCount - 2));
    const std::string text = expression::describe_clamping(s, 200);
    EXPECT_LE(text.size(), 200u) << text;
    EXPECT_NE(text.find("66 FAP values beyond the face's range clamped (open_jaw in frame 0, "), std::string::npos)
        << text;
    EXPECT_NE(text.find(" more FAPs)"), std::string::npos) << text;
}

}  // namespace
