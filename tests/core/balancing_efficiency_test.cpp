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

struct SpinRun {
  double mean_idle = 0.0, mean_frame_ms = 0.0, mean_rendering = 0.0;
};

// 200 frames of a spinning camera over tracers of the given speeds and fixed costs per band; the means
// are over the frames after the first `warmup`.
SpinRun spin(const std::string& balancer, const std::vector<double>& speeds, const std::vector<double>& fixed_ms,
             double degrees_per_frame, bool row_work, double ms_per_cost = 0.05, int warmup = 10) {
  auto model = std::make_shared<SpinSceneCostModel>(1);
  std::vector<std::unique_ptr<Tracer>> tracers;
  for (size_t i = 0; i < speeds.size(); ++i) {
    SimulatedTracerOptions o;
    o.name = "sim" + std::to_string(i);
    o.seed = 1001 + i;
    o.speed = speeds[i];
    o.fixed_ms = fixed_ms[i];
    o.ms_per_cost = ms_per_cost;
    o.noise = 0.02;
    o.report_row_work = row_work;
    tracers.push_back(std::make_unique<SimulatedTracer>(model, o));
  }
  RendererOptions options;
  options.balancer = balancer;
  options.use_reported_time = true;
  Renderer renderer(std::move(tracers), options);
  FrameBuffer fb;
  SpinRun run;
  int counted = 0;
  for (int f = 0; f < 200; ++f) {
    BandJob job;
    job.camera = spin_camera(4, 720, f * degrees_per_frame * std::numbers::pi / 180.0);
    job.params.frame_index = static_cast<kuint>(f);
    const FrameStats stats = renderer.render(job, fb);
    EXPECT_EQ(stats.dropped, 0);
    if (f < warmup) continue;
    run.mean_idle += stats.idle_percent;
    run.mean_frame_ms += stats.frame_ms;
    for (const TracerFrameStats& t : stats.tracers) run.mean_rendering += t.outcome == TracerOutcome::rendered;
    ++counted;
  }
  run.mean_idle /= counted;
  run.mean_frame_ms /= counted;
  run.mean_rendering /= counted;
  return run;
}

// Mean idle % of `count` tracers (the second at speed 0.7) reporting their rows' work, after 5 frames.
double mean_idle(const std::string& balancer, int count, double degrees_per_frame) {
  std::vector<double> speeds(size_t(count), 1.0);
  if (count > 1) speeds[1] = 0.7;
  return spin(balancer, speeds, std::vector<double>(size_t(count), 0.0), degrees_per_frame, true, 0.05, 5).mean_idle;
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


// The simulated target: speeds 1 and 0.02 with a 2 ms fixed cost on the slow one. Whole Cost
// benches the slow tracer (mean idle <= 2 %) and its frames are as fast as the fast tracer's alone,
// where the other balancers keep the slow one and make the frame slower. Both a 63 ms frame (default
// cost) and a 6 ms one (GPU-like).
TEST(BalancingEfficiency, WholeCostBenchesASlowTracerWithAFixedCost) {
  for (double ms_per_cost : {0.05, 0.005}) {
    for (double degrees : {2.0, 10.0}) {
      const SpinRun alone = spin("none", {1.0}, {0.0}, degrees, true, ms_per_cost);
      const SpinRun whole = spin("whole-cost", {1.0, 0.02}, {0.0, 2.0}, degrees, true, ms_per_cost);
      const SpinRun smooth = spin("perfect-smooth", {1.0, 0.02}, {0.0, 2.0}, degrees, true, ms_per_cost);
      const std::string where = std::to_string(ms_per_cost) + " ms/cost, " + std::to_string(degrees) + " deg/frame";
      EXPECT_LE(whole.mean_idle, 2.0) << where;
      EXPECT_LT(whole.mean_rendering, 1.05) << where << ": the slow tracer should be benched";
      EXPECT_LT(whole.mean_frame_ms, 1.01 * alone.mean_frame_ms) << where;
      EXPECT_LT(whole.mean_frame_ms, smooth.mean_frame_ms) << where;
    }
  }
}

// With equal tracers (no fixed cost), Whole Cost is Perfect Smooth's equal or better, with per-row
// work counts and without.
TEST(BalancingEfficiency, WholeCostMatchesPerfectSmoothOnEqualTracers) {
  for (bool row_work : {true, false}) {
    for (double degrees : {2.0, 10.0}) {
      const SpinRun whole = spin("whole-cost", {1.0, 1.0, 1.0}, {0.0, 0.0, 0.0}, degrees, row_work);
      const SpinRun smooth = spin("perfect-smooth", {1.0, 1.0, 1.0}, {0.0, 0.0, 0.0}, degrees, row_work);
      EXPECT_LT(whole.mean_idle, smooth.mean_idle * 1.05 + 0.1) << degrees << " deg/frame, row work " << row_work;
      EXPECT_NEAR(whole.mean_rendering, 3.0, 1e-9);
    }
  }
}
