#include <gtest/gtest.h>

#include <random>

#include "cohort/core/workload_scaler.h"

using namespace cohort::core;

namespace {

// Frame time of a device that needs ms_per_spp per sample at full resolution, with some jitter.
struct Device {
  double ms_per_spp;
  std::mt19937 rng{7};
  std::normal_distribution<double> jitter{1.0, 0.03};
  double frame_ms(const WorkloadSetting& s) { return ms_per_spp * s.spp * s.render_scale * s.render_scale * jitter(rng); }
};

}  // namespace

TEST(WorkloadScaler, SettlesInsideTheBandWithoutOscillating) {
  WorkloadScalerOptions o;
  o.target_ms = 33.0;
  WorkloadScaler scaler(o, {1, 1.0});
  Device d{3.1};
  int changes_late = 0;
  WorkloadSetting s = scaler.current();
  for (int frame = 0; frame < 300; ++frame) {
    const WorkloadSetting next = scaler.update(d.frame_ms(s));
    if (frame >= 100 && !(next == s)) ++changes_late;
    s = next;
  }
  EXPECT_EQ(s.spp, 10);  // 31 ms: the most that fits the target
  EXPECT_EQ(changes_late, 0);
}

TEST(WorkloadScaler, BacksOffWhenTheDeviceSlowsDown) {
  WorkloadScalerOptions o;
  o.target_ms = 20.0;
  WorkloadScaler scaler(o, {16, 1.0});
  Device d{1.0};
  WorkloadSetting s = scaler.current();
  for (int frame = 0; frame < 100; ++frame) s = scaler.update(d.frame_ms(s));
  EXPECT_EQ(s.spp, 20);  // 16 ms is under the band (18-22 ms): it grows to what the target fits
  d.ms_per_spp = 4.0;    // e.g. a heavier part of the map
  for (int frame = 0; frame < 100; ++frame) s = scaler.update(d.frame_ms(s));
  EXPECT_EQ(s.spp, 5);
  EXPECT_LT(scaler.smoothed_ms(), 22.0);
}

TEST(WorkloadScaler, LowersResolutionOnceSppIsAtItsMinimum) {
  WorkloadScalerOptions o;
  o.target_ms = 10.0;
  o.scale_resolution = true;
  o.min_scale = 0.25;
  WorkloadScaler scaler(o, {2, 1.0});
  Device d{20.0};  // even 1 spp at full resolution takes twice the target
  WorkloadSetting s = scaler.current();
  for (int frame = 0; frame < 200; ++frame) s = scaler.update(d.frame_ms(s));
  EXPECT_EQ(s.spp, 1);
  EXPECT_LT(s.render_scale, 0.75);
  EXPECT_GT(s.render_scale, 0.6);
  d.ms_per_spp = 2.0;  // the load goes away: full resolution first, then more samples
  for (int frame = 0; frame < 200; ++frame) s = scaler.update(d.frame_ms(s));
  EXPECT_DOUBLE_EQ(s.render_scale, 1.0);
  EXPECT_EQ(s.spp, 5);
}

TEST(WorkloadScaler, RejectsNonsense) {
  WorkloadScalerOptions o;
  o.target_ms = 0.0;
  EXPECT_THROW(WorkloadScaler{o}, std::invalid_argument);
  o.target_ms = 10.0;
  o.min_spp = 4;
  o.max_spp = 2;
  EXPECT_THROW(WorkloadScaler{o}, std::invalid_argument);
}
