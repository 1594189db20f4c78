// The parity helper never calls a broken result close.
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/expect_error.h"
#include "support/parity.h"

namespace {

using emoface::testing::max_abs_diff;

TEST(Parity, MaxAbsDiffIsInfiniteOnNaNAndOnSizeMismatch) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    struct Case {
        const char* what;
        std::vector<float> a, b;
        double expected;
    };
    const Case cases[] = {
        {"equal", {0.f, 1.f, 2.f}, {0.f, 1.f, 2.f}, 0.0},
        {"largest difference", {0.f, 1.f, 2.f}, {0.5f, 1.f, 4.f}, 2.0},
        {"both empty", {}, {}, 0.0},
        {"NaN on the left", {0.f, nan}, {0.f, 1.f}, inf},
        {"NaN on the right", {0.f, 1.f}, {nan, 1.f}, inf},
        {"NaN on both sides", {nan}, {nan}, inf},
        {"left shorter", {0.f}, {0.f, 0.f}, inf},
        {"right empty", {0.f}, {}, inf},
    };
    for (const Case& c : cases) EXPECT_EQ(max_abs_diff(c.a, c.b), c.expected) << c.what;
}

TEST(ExpectError, ThrownMessageNamesWhatHappened) {
    using emoface::testing::thrown_message;
    EXPECT_EQ(thrown_message<std::invalid_argument>([] { throw std::invalid_argument("bad"); }), "bad");
    EXPECT_EQ(thrown_message<std::invalid_argument>([] {}), "(no error)");
    EXPECT_EQ(thrown_message<std::invalid_argument>([] { throw std::runtime_error("other"); }),
              "(another exception: other)");
    emoface::testing::expect_error<std::invalid_argument>([] { throw std::invalid_argument("bad"); }, "bad");
}

}  // namespace
