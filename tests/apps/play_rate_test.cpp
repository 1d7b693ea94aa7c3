#include "play_rate.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace cohort::app
