// emoface::parallel_for over the shared pool: every index once, nesting,
// exceptions, callers on several threads.
#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "emoface/common/parallel.h"

namespace emoface {
namespace {

// How often each index of [0, count) was handed out.
std::vector<int> visits(int count, int chunk) {
    std::vector<std::atomic<int>> seen(static_cast<std::size_t>(count > 0 ? count : 0));
    parallel_for(count, chunk, [&](int begin, int end) {
        for (int i = begin; i < end; ++i) seen[static_cast<std::size_t>(i)].fetch_add(1);
    });
    std::vector<int> out;
    for (const auto& s : seen) out.push_back(s.load());
    return out;
}

struct RangeCase {
    int count, chunk;
};

class ParallelFor : public ::testing::TestWithParam<RangeCase> {};

TEST_P(ParallelFor, HandsOutEveryIndexExactlyOnce) {
    const RangeCase c = GetParam();
    const std::vector<int> seen = visits(c.count, c.chunk);
    ASSERT_EQ(seen.size(), static_cast<std::size_t>(c.count));
    for (int i = 0; i < c.count; ++i) EXPECT_EQ(seen[static_cast<std::size_t>(i)], 1) << "index " << i;
}

INSTANTIATE_TEST_SUITE_P(Ranges, ParallelFor,
                         ::testing::Values(RangeCase{0, 1}, RangeCase{1, 1}, RangeCase{7, 1}, RangeCase{1000, 1},
                                           RangeCase{1000, 7}, RangeCase{1000, 1000}, RangeCase{1000, 5000},
                                           RangeCase{5, 0}),
                         [](const auto& info) {
                             return "count" + std::to_string(info.param.count) + "_chunk" +
                                    std::to_string(info.param.chunk);
                         });

TEST(ParallelFor, ChunksNeverExceedTheChunkSizeOnThePool) {
    if (parallel_threads() < 2) GTEST_SKIP() << "one thread: the whole range is one call";
    std::atomic<int> largest{0};
    parallel_for(100, 3, [&](int begin, int end) {
        int seen = largest.load();
        while (end - begin > seen && !largest.compare_exchange_weak(seen, end - begin)) {
        }
    });
    EXPECT_LE(largest.load(), 3);
}

TEST(ParallelFor, ANestedCallRunsInlineAndCoversItsRange) {
    std::vector<std::atomic<int>> seen(64 * 32);
    parallel_for(64, 1, [&](int begin, int end) {
        for (int outer = begin; outer < end; ++outer)
            parallel_for(32, 4, [&](int b, int e) {
                for (int inner = b; inner < e; ++inner) seen[static_cast<std::size_t>(outer * 32 + inner)]++;
            });
    });
    for (std::size_t i = 0; i < seen.size(); ++i) ASSERT_EQ(seen[i].load(), 1) << "index " << i;
}

TEST(ParallelFor, AChunksExceptionReachesTheCallerAndThePoolStaysUsable) {
    try {
        parallel_for(1000, 1, [](int begin, int) {
            if (begin == 500) throw std::runtime_error("chunk 500 failed");
        });
        FAIL() << "expected the chunk's exception";
    } catch (const std::runtime_error& e) {
        EXPECT_STREQ(e.what(), "chunk 500 failed");
    }
    const std::vector<int> seen = visits(300, 2);
    for (int i = 0; i < 300; ++i) ASSERT_EQ(seen[static_cast<std::size_t>(i)], 1) << "index " << i;
}

TEST(ParallelFor, CallersOnSeveralThreadsEachGetTheirWholeRange) {
    constexpr int kCallers = 4, kCount = 2000;
    std::vector<long long> sums(kCallers, 0);
    std::vector<std::thread> callers;
    for (int c = 0; c < kCallers; ++c)
        callers.emplace_back([&, c] {
            for (int round = 0; round < 20; ++round) {
                std::atomic<long long> sum{0};
                parallel_for(kCount, 16, [&](int begin, int end) {
                    long long s = 0;
                    for (int i = begin; i < end; ++i) s += i;
                    sum += s;
                });
                sums[static_cast<std::size_t>(c)] += sum.load();
            }
        });
    for (auto& t : callers) t.join();
    const long long expected = 20LL * kCount * (kCount - 1) / 2;
    for (int c = 0; c < kCallers; ++c) EXPECT_EQ(sums[static_cast<std::size_t>(c)], expected) << "caller " << c;
}

TEST(ParallelFor, ThePoolHasAtLeastTheCallingThread) { EXPECT_GE(parallel_threads(), 1); }

}  // namespace
}  // namespace emoface
