// The rule both GPU tracers split a wavefront's band by (cohort/tracers/wave_lanes.h): whole 8-row groups,
// at least 32 rows a lane, no more lanes than asked, and lanes that cover the band exactly.
#include "cohort/tracers/wave_lanes.h"

#include <gtest/gtest.h>

using namespace cohort::tracers;

TEST(WaveLanes, LanesAreWholeGroupsOfAtLeast32RowsCoveringTheBand) {
  EXPECT_EQ(wave_lane_count(2, 63), 1) << "two lanes need 64 rows";
  EXPECT_EQ(wave_lane_count(2, 64), 2);
  EXPECT_EQ(wave_lane_count(4, 100), 3);
  EXPECT_EQ(wave_lane_count(4, 10), 1);
  EXPECT_EQ(wave_lane_count(1, 1080), 1);
  for (unsigned rows : {64u, 65u, 75u, 125u, 270u, 1080u})
    for (int most = 1; most <= 4; ++most) {
      const int lanes = wave_lane_count(most, rows);
      EXPECT_EQ(wave_lane_first_row(rows, lanes, 0), 0u);
      EXPECT_EQ(wave_lane_first_row(rows, lanes, lanes), rows);
      for (int lane = 0; lane < lanes; ++lane) {
        const unsigned first = wave_lane_first_row(rows, lanes, lane), end = wave_lane_first_row(rows, lanes, lane + 1);
        EXPECT_EQ(first % 8u, 0u) << rows << " rows, lane " << lane;
        EXPECT_GE(end - first, lane + 1 < lanes ? 24u : 1u) << rows << " rows, lane " << lane;
        EXPECT_LT(first, end) << rows << " rows, lane " << lane;
      }
    }
  EXPECT_EQ(wave_lane_first_row(75, 2, 1), 32u) << "the split the OpenCL and CUDA lanes have always made";
  EXPECT_EQ(wave_lane_first_row(125, 3, 1), 40u);
  EXPECT_EQ(wave_lane_first_row(125, 3, 2), 80u);
}
