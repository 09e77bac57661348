#include "core/thread_pool.h"

#include <gtest/gtest.h>

#include <atomic>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "core/random.h"

namespace {

// Per-item seeded streams + per-item outputs: the result cannot depend on the thread count.
std::vector<std::uint32_t> run(unsigned threads, std::size_t grain) {
  gi::ThreadPool pool(threads);
  std::vector<std::uint32_t> out(10007);
  for (int repeat = 0; repeat < 3; ++repeat) {
    pool.parallel_for(
        out.size(),
        [&](std::size_t i) {
          gi::Pcg32 rng = gi::Pcg32::for_item(42, i);
          std::uint32_t acc = 0;
          for (int k = 0; k < 16; ++k) acc ^= rng.next_u32();
          out[i] = acc;
        },
        grain);
  }
  return out;
}

TEST(ThreadPool, ResultsAreBitIdenticalForAnyThreadCount) {
  const auto one = run(1, 1);
  EXPECT_EQ(one, run(2, 1));
  EXPECT_EQ(one, run(4, 64));
  EXPECT_EQ(one, run(7, 1000));
}

TEST(ThreadPool, VisitsEveryItemExactlyOnce) {
  gi::ThreadPool pool(3);
  std::vector<std::atomic<int>> visits(5000);
  pool.parallel_for(
      visits.size(), [&](std::size_t i) { visits[i].fetch_add(1); }, 7);
  for (const auto& v : visits) ASSERT_EQ(v.load(), 1);
  pool.parallel_for(0, [&](std::size_t) { FAIL() << "no items"; });
}

// Issue-20 inputs: an absurd thread count is clamped, not a crash; an exception thrown by
// an item reaches the caller instead of terminating the process, and the pool stays usable.
TEST(ThreadPool, AbsurdThreadCountsAreClampedAndItemExceptionsReachTheCaller) {
  gi::ThreadPool huge(4000000000u);
  EXPECT_EQ(huge.size(), gi::ThreadPool::kMaxThreads);
  gi::ThreadPool pool(2);
  EXPECT_THROW(pool.parallel_for(1000,
                                 [](std::size_t i) {
                                   if (i == 517) throw std::runtime_error("item 517");
                                 }),
               std::runtime_error);
  std::vector<std::atomic<int>> visits(100);
  pool.parallel_for(visits.size(), [&](std::size_t i) { visits[i].fetch_add(1); });
  for (const auto& v : visits) ASSERT_EQ(v.load(), 1);
}

TEST(Pcg32, StreamsForDifferentItemsDiffer) {
  gi::Pcg32 a = gi::Pcg32::for_item(1, 0);
  gi::Pcg32 b = gi::Pcg32::for_item(1, 1);
  int same = 0;
  for (int i = 0; i < 64; ++i) same += a.next_u32() == b.next_u32();
  EXPECT_LT(same, 2);
}

TEST(Pcg32, FloatsAreUniformInUnitInterval) {
  gi::Pcg32 rng = gi::Pcg32::for_item(9, 9);
  double sum = 0.0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    const float u = rng.next_float();
    ASSERT_GE(u, 0.0f);
    ASSERT_LT(u, 1.0f);
    sum += static_cast<double>(u);
  }
  EXPECT_NEAR(sum / n, 0.5, 0.005);  // ~5 sigma of the mean of n uniforms
}

}  // namespace
