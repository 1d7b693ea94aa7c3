#include "play_rate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace cohort::app {
namespace {

TEST(PlayRate, LeavesTheWarmUpOutAndTakesMedianAndP95) {
  PlayRate rate(3);
  for (double ms : {500.0, 400.0, 300.0}) rate.frame(ms);  // warm-up: loading and the first frames
  for (int i = 1; i <= 100; ++i) rate.frame(static_cast<double>(i));
  EXPECT_EQ(rate.counted(), 100u);
  EXPECT_DOUBLE_EQ(rate.median_ms(), 50.5);  // between ranks 49 and 50 of 1..100 (order_statistics.h)
  EXPECT_NEAR(rate.p95_ms(), 95.05, 1e-9);   // rank 0.95 * 99 = 94.05
}

TEST(PlayRate, IgnoresIntervalsThatAreNotTimes) {
  PlayRate rate(0);
  rate.frame(std::numeric_limits<double>::quiet_NaN());
  rate.frame(-1.0);
  rate.frame(0.0);
  rate.frame(std::numeric_limits<double>::infinity());
  rate.frame(20.0);
  EXPECT_EQ(rate.counted(), 1u);
  EXPECT_DOUBLE_EQ(rate.median_ms(), 20.0);
}

TEST(PlayRate, SummaryNamesRateSizeAndTarget) {
  PlayRate rate(1);
  rate.frame(1000.0);
  for (int i = 0; i < 10; ++i) rate.frame(25.0);
  const std::string text = rate.summary(11, 1280, 720, 320, 180, 0.25, 2, 30);
  EXPECT_NE(text.find("played 11 frames in a 1280x720 window"), std::string::npos) << text;
  EXPECT_NE(text.find("median 25.0 ms (40.0 fps)"), std::string::npos) << text;
  EXPECT_NE(text.find("rendering 320x180 (scale 0.25), 2 spp, target 30 fps"), std::string::npos) << text;
  EXPECT_NE(PlayRate(5).summary(2, 64, 64, 16, 16, 0.25, 1, 0).find("too few to time"), std::string::npos);
}

TEST(PlayRate, CpuTimePerFrameAndCoresOverTheCountedFrames) {
  PlayRate rate(2);
  rate.frame(100.0, 500.0);  // warm-up: not counted
  rate.frame(100.0, 500.0);
  rate.frame(50.0, 90.0);
  rate.frame(50.0, 70.0);
  rate.frame(40.0);  // no CPU time: counts for the rate only
  EXPECT_EQ(rate.counted(), 3u);
  EXPECT_DOUBLE_EQ(rate.cpu_ms_per_frame(), 80.0);
  EXPECT_DOUBLE_EQ(rate.cores_busy(), 1.6);  // 160 ms of CPU in 100 ms
  EXPECT_NE(rate.summary(5, 1280, 720, 320, 180, 0.25, 1, 30).find("over the last 3, CPU 80.0 ms a frame (1.60 cores)"),
            std::string::npos)
      << rate.summary(5, 1280, 720, 320, 180, 0.25, 1, 30);
  PlayRate no_cpu(0);
  no_cpu.frame(30.0);
  EXPECT_EQ(no_cpu.summary(1, 64, 64, 16, 16, 1.0, 1, 0).find("CPU"), std::string::npos);
}

TEST(PlayRate, ProcessCpuTimeAdvancesWithWork) {
  const double before = process_cpu_ms();
  volatile double sink = 0.0;
  while (process_cpu_ms() - before < 20.0)
    for (int i = 0; i < 100000; ++i) sink = sink + std::sqrt(static_cast<double>(i));
  EXPECT_GE(process_cpu_ms() - before, 20.0);
  EXPECT_GT(before, 0.0);
}

}  // namespace
}  // namespace cohort::app
