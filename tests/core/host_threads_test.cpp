#include "cohort/core/host_threads.h"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

using cohort::core::HostThreads;

TEST(HostThreads, EveryIndexRunsExactlyOnceInContiguousRanges) {
  HostThreads pool(3);
  for (size_t count : {0u, 1u, 7u, 100u, 4096u, 100003u}) {
    std::vector<std::atomic<int>> visits(count);
    std::atomic<int> ranges{0};
    pool.for_ranges(count, 10, [&](size_t begin, size_t end) {
      ASSERT_LT(begin, end);
      ++ranges;
      for (size_t i = begin; i < end; ++i) ++visits[i];
    });
    for (size_t i = 0; i < count; ++i) ASSERT_EQ(visits[i].load(), 1) << "index " << i << " of " << count;
    EXPECT_LE(ranges.load(), static_cast<int>(pool.threads())) << count;
    if (count >= 40) { EXPECT_GT(ranges.load(), 1) << "work this size is split"; }
  }
}

TEST(HostThreads, SmallWorkRunsOnTheCallingThread) {
  HostThreads pool(3);
  std::thread::id ran_on;
  pool.for_ranges(5, 10, [&](size_t, size_t) { ran_on = std::this_thread::get_id(); });
  EXPECT_EQ(ran_on, std::this_thread::get_id());
}

TEST(HostThreads, CallersOnSeveralThreadsTakeTurns) {
  HostThreads pool(2);
  std::vector<std::thread> callers;
  std::atomic<long> total{0};
  for (int c = 0; c < 4; ++c)
    callers.emplace_back([&] {
      for (int round = 0; round < 50; ++round)
        pool.for_ranges(1000, 10, [&](size_t begin, size_t end) { total += static_cast<long>(end - begin); });
    });
  for (std::thread& t : callers) t.join();
  EXPECT_EQ(total.load(), 4L * 50 * 1000);
}
