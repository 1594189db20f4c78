#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "emoface/common/error.h"
#include "emoface/fap/fap_stream.h"
#include "support/expect_error.h"

namespace emoface::fap {
namespace {

using emoface::testing::expect_error;

TEST(FapFrame, SetGetHasClear) {
    FapFrame f;
    EXPECT_FALSE(f.has(31));
    f.set(31, 120);
    EXPECT_TRUE(f.has(31));
    EXPECT_EQ(f.get(31), 120);
    EXPECT_EQ(f.values[30], 120);
    EXPECT_EQ(f.transmitted_count(), 1);
    f.set_expression({3, 40, 0, 0, 0, 0});
    EXPECT_TRUE(f.has(2));
    EXPECT_EQ(f.expression.intensity1, 40);
    f.clear(31);
    f.clear(2);
    EXPECT_FALSE(f.has(31));
    EXPECT_EQ(f.get(31), 0);
    EXPECT_EQ(f.expression, Expression{});
    EXPECT_EQ(f.transmitted_count(), 0);
}

TEST(FapFrame, NumberErrors) {
    FapFrame f;
    expect_error<Error>([&] { f.has(0); }, "fap: FapFrame::has: expected a FAP number 1..68, found 0");
    expect_error<Error>([&] { f.get(69); }, "fap: FapFrame::get: expected a FAP number 1..68, found 69");
    expect_error<Error>([&] { f.set(2, 1); }, "fap: FapFrame::set: expected a FAP number 3..68, found 2");
    expect_error<Error>([&] { f.clear(-1); }, "fap: FapFrame::clear: expected a FAP number 1..68, found -1");
}

TEST(FapFrame, EqualityComparesTransmittedContentOnly) {
    FapFrame a, b;
    a.set(5, 10);
    b.set(5, 10);
    b.values[6] = 99;             // not transmitted: ignored
    b.expression.intensity1 = 7;  // FAP 2 not transmitted: ignored
    EXPECT_EQ(a, b);
    b.set(5, 11);
    EXPECT_NE(a, b);
    b.set(5, 10);
    b.number = 1;
    EXPECT_NE(a, b);
    b.number = 0;
    b.set_viseme({1, 0, 0, 0});
    EXPECT_NE(a, b);
    a.set_viseme({1, 0, 0, 0});
    EXPECT_EQ(a, b);
}

TEST(ExpressionNames, Codes) {
    EXPECT_EQ(expression_name(0), "neutral");
    EXPECT_EQ(expression_name(3), "anger");
    EXPECT_EQ(expression_name(6), "surprise");
    EXPECT_EQ(expression_name(7), "");
    EXPECT_EQ(viseme_name(1), "p b m");
    EXPECT_EQ(viseme_name(14), "U");
    EXPECT_EQ(viseme_name(-1), "");
}

// Three frames at 10 fps: FAP 3 sent in 0 and 2, FAP 31 only in 1, FAP 2
// (expression) only in 0.
FapStream three_frames() {
    FapStream s;
    s.fps = 10;
    s.frames.resize(3);
    s.frames[0].number = 1;
    s.frames[0].set(3, 100);
    s.frames[0].set_expression({1, 63, 0, 0, 0, 0});
    s.frames[1].number = 2;
    s.frames[1].set(31, 50);
    s.frames[2].number = 3;
    s.frames[2].set(3, 300);
    return s;
}

TEST(FapStream, DurationAndFrameTime) {
    const FapStream s = three_frames();
    EXPECT_DOUBLE_EQ(s.duration(), 0.3);
    EXPECT_DOUBLE_EQ(s.frame_time(2), 0.2);
    EXPECT_EQ(FapStream{}.duration(), 0);
}

TEST(FapStream, ResolvedKeepsLastTransmittedValue) {
    const FapStream s = three_frames();
    const FapFrame r1 = s.resolved(1);
    EXPECT_TRUE(r1.has(3));
    EXPECT_EQ(r1.get(3), 100);  // kept from frame 0
    EXPECT_EQ(r1.get(31), 50);
    EXPECT_TRUE(r1.has(2));
    EXPECT_EQ(r1.expression.select1, 1);  // FAP 2 kept as a whole
    EXPECT_EQ(r1.number, 2);
    EXPECT_FALSE(r1.has(4));  // never transmitted: neutral, not in the mask
    const FapFrame r2 = s.resolved(2);
    EXPECT_EQ(r2.get(3), 300);
    EXPECT_EQ(r2.get(31), 50);
    const FapFrame r0 = s.resolved(0);
    EXPECT_FALSE(r0.has(31));
    EXPECT_EQ(r0.get(31), 0);
    expect_error<Error>([&] { s.resolved(3); },
              "fap: FapStream::resolved: expected a frame index below 3, found 3");
}

TEST(FapStream, ResolvedIgnoresStaleUntransmittedValues) {
    FapStream s;
    s.frames.resize(2);
    s.frames[0].set(10, 5);
    s.frames[1].values[9] = 77;  // written without the mask: means nothing
    EXPECT_EQ(s.resolved(1).get(10), 5);
    s.frames[1].values[11] = 77;
    EXPECT_EQ(s.resolved(1).get(12), 0);
}

struct SampleCase {
    double seconds;
    double fap3, fap31;
    bool has31;
    long long number;
};

TEST(FapStream, SampleInterpolatesResolvedFrames) {
    const FapStream s = three_frames();
    // Frame k at k / 10 s. FAP 31 is first sent in frame 1, so between frames
    // 0 and 1 it rises from neutral; FAP 3 is held at 100 through frame 1.
    const SampleCase cases[] = {
        {-1.0, 100, 0, false, 1},   // before the start: frame 0
        {0.0, 100, 0, false, 1},
        {0.025, 100, 12.5, true, 1},
        {0.05, 100, 25, true, 1},
        {0.1, 100, 50, true, 2},
        {0.15, 200, 50, true, 2},
        {0.2, 300, 50, true, 3},
        {0.29, 300, 50, true, 3},  // the last frame is held
        {99.0, 300, 50, true, 3},
    };
    for (const SampleCase& c : cases) {
        SCOPED_TRACE(c.seconds);
        const FapFrame f = s.sample(c.seconds);
        EXPECT_NEAR(f.get(3), c.fap3, 1e-9);
        EXPECT_NEAR(f.get(31), c.fap31, 1e-9);
        EXPECT_EQ(f.has(31), c.has31);
        EXPECT_EQ(f.number, c.number);
        EXPECT_TRUE(f.has(2));
        EXPECT_EQ(f.expression.intensity1, 63);
    }
}

TEST(FapStream, SampleStepsVisemeAndExpression) {
    FapStream s;
    s.fps = 1;
    s.frames.resize(3);
    s.frames[1].set_expression({3, 20, 0, 0, 0, 0});
    s.frames[2].set_expression({4, 60, 0, 0, 0, 0});
    EXPECT_FALSE(s.sample(0.5).has(2));  // not yet transmitted at frame 0
    EXPECT_EQ(s.sample(1.0).expression.select1, 3);
    EXPECT_EQ(s.sample(1.99).expression.select1, 3);
    EXPECT_EQ(s.sample(1.99).expression.intensity1, 20);
    EXPECT_EQ(s.sample(2.0).expression.select1, 4);
}

TEST(FapStream, SampleEdgeCases) {
    const FapFrame empty = FapStream{}.sample(1.0);
    EXPECT_TRUE(empty.mask.none());
    FapStream s = three_frames();
    expect_error<Error>([&] { s.sample(std::nan("")); },
              "fap: FapStream::sample: expected a finite time in seconds, found nan");
    expect_error<Error>([&] { s.sample(std::numeric_limits<double>::infinity()); },
              "fap: FapStream::sample: expected a finite time in seconds, found inf");
    s.fps = 0;
    expect_error<Error>([&] { s.sample(0.0); },
              "fap: FapStream::sample: expected a frame rate > 0, found 0");
    // Huge times and frame rates never index past the frames.
    s.fps = 1e300;
    EXPECT_EQ(s.sample(1e300).get(3), 300);
}

// resolve_untransmitted (one pass) agrees with resolved(k) (walking back) on
// random sparse streams.
TEST(FapStream, ResolveUntransmittedMatchesResolved) {
    std::mt19937 rng(7);
    std::uniform_int_distribution<int> fap(1, kFapCount), value(-500, 500), count(0, 5);
    for (int trial = 0; trial < 20; ++trial) {
        FapStream s;
        s.frames.resize(40);
        for (FapFrame& f : s.frames) {
            for (int n = count(rng); n > 0; --n) {
                const int k = fap(rng);
                if (k == 1)
                    f.set_viseme({value(rng) & 7, 0, 0, 0});
                else if (k == 2)
                    f.set_expression({value(rng) & 3, 10, 0, 0, 0, 0});
                else
                    f.set(k, value(rng));
            }
        }
        const FapStream all = resolve_untransmitted(s);
        for (std::size_t k = 0; k < s.frames.size(); ++k) {
            const FapFrame one = s.resolved(k);
            ASSERT_EQ(all.frames[k], one) << "trial " << trial << " frame " << k;
            ASSERT_EQ(all.frames[k].viseme, one.viseme);
            ASSERT_EQ(all.frames[k].expression, one.expression);
        }
    }
}

}  // namespace
}  // namespace emoface::fap
