// The claim `cohort bench balance` makes, as a regression test on a short run: with simulated tracers
// on a spinning camera, Row Cost (with per-row work counts) leaves less idle time than Perfect Smooth,
// which leaves less than no balancing.
#include <gtest/gtest.h>

#include <map>
#include <numbers>

#include "cohort/core/renderer.h"
#include "cohort/core/simulated_tracer.h"

using namespace cohort::core;

namespace {

double mean_idle(const std::string& balancer, int count, double degrees_per_frame) {
  auto model = std::make_shared<SpinSceneCostModel>(1);
  std::vector<std::unique_ptr<Tracer>> tracers;
  for (int i = 0; i < count; ++i) {
    SimulatedTracerOptions o;
    o.name = "sim" + std::to_string(i);
    o.seed = 1001 + static_cast<uint64_t>(i);
    o.speed = i == 1 ? 0.7 : 1.0;
    o.noise = 0.02;
    o.report_row_work = true;
    tracers.push_back(std::make_unique<SimulatedTracer>(model, o));
  }
  RendererOptions options;
  options.balancer = balancer;
  options.use_reported_time = true;
  Renderer renderer(std::move(tracers), options);
  FrameBuffer fb;
  double sum = 0.0;
  int counted = 0;
  for (int f = 0; f < 200; ++f) {
    BandJob job;
    job.camera = spin_camera(4, 720, f * degrees_per_frame * std::numbers::pi / 180.0);
    job.params.frame_index = static_cast<kuint>(f);
    const FrameStats stats = renderer.render(job, fb);
    EXPECT_EQ(stats.dropped, 0);
    if (f >= 5) {
      sum += stats.idle_percent;
      ++counted;
    }
  }
  return sum / counted;
}

}  // namespace

TEST(BalancingEfficiency, RowCostBeatsPerfectSmoothBeatsNone) {
  for (double speed : {2.0, 10.0}) {
    for (int count : {2, 3}) {
      const double none = mean_idle("none", count, speed);
      const double smooth = mean_idle("perfect-smooth", count, speed);
      const double row_cost = mean_idle("row-cost", count, speed);
      EXPECT_LT(smooth, none) << count << " tracers, " << speed << " deg/frame";
      EXPECT_LT(row_cost, smooth) << count << " tracers, " << speed << " deg/frame";
      EXPECT_LT(row_cost, 5.0) << count << " tracers, " << speed << " deg/frame";
    }
  }
}
