#include "balance_bench.h"

#include <algorithm>
#include <cstdio>
#include <chrono>
#include <numbers>
#include <optional>
#include <stdexcept>

#include "cohort/core/frame_defaults.h"
#include "cohort/core/frame_pipeline.h"
#include "cohort/core/renderer.h"
#include "cohort/core/simulated_tracer.h"
#include "real_tracers.h"

namespace cohort::app {

double path_degrees_per_frame(const std::string& path) {
  // Slow: a full turn in 180 frames (3 s at 60 Hz); fast: a full turn in 36 frames, where a band's
  // content changes a lot between frames and last frame's timing is a poor guide.
  if (path == "slow") return 2.0;
  if (path == "fast") return 10.0;
  throw std::invalid_argument("unknown camera path '" + path + "' (known: slow, fast)");
}

namespace {

BalanceBenchRun run_one(const BalanceBenchConfig& config, const std::string& path, int count, const std::string& balancer) {
  auto model = std::make_shared<core::SpinSceneCostModel>(config.seed);
  std::vector<std::unique_ptr<core::Tracer>> tracers;
  glm::vec3 eye(0.0f);
  if (!config.real.empty()) {
    RealTracers real = make_real_tracers(config.real, config.real_scene);
    tracers = std::move(real.tracers);
    eye = real.eye;
  } else {
    for (int i = 0; i < count; ++i) {
      core::SimulatedTracerOptions o;
      o.name = "sim" + std::to_string(i);
      o.speed = config.speeds[static_cast<size_t>(i) % config.speeds.size()];
      o.fixed_ms = config.fixed_ms[static_cast<size_t>(i) % config.fixed_ms.size()];
      o.ms_per_cost = config.ms_per_cost;
      o.noise = config.noise;
      o.report_row_work = config.row_work;
      o.clock = config.clock == "sleep"   ? core::SimulatedClock::sleep
                : config.clock == "spin" ? core::SimulatedClock::spin
                                         : core::SimulatedClock::virtual_time;
      o.time_scale = config.time_scale;
      o.row_work_error = config.row_work_error;
      o.seed = config.seed * 1000 + static_cast<uint64_t>(i) + 1;
      tracers.push_back(std::make_unique<core::SimulatedTracer>(model, o));
    }
  }
  core::RendererOptions options;
  options.balancer = balancer;
  options.balancer_options = config.balancer_options;
  options.use_reported_time = config.real.empty() && config.clock == "virtual";
  options.frames_in_flight = config.frames_in_flight;
  core::Renderer renderer(std::move(tracers), options);
  core::FramePipeline pipeline(renderer);

  BalanceBenchRun run;
  run.path = path;
  run.balancer = balancer;
  run.tracers = renderer.tracer_count();
  const double step = path_degrees_per_frame(path) * std::numbers::pi / 180.0;
  core::FrameBuffer frame;
  int counted = 0, intervals = 0;
  std::optional<std::chrono::steady_clock::time_point> last_delivery;
  auto take = [&](const core::FrameStats& stats) {
    const int f = static_cast<int>(stats.frame);
    const auto now = std::chrono::steady_clock::now();
    if (last_delivery && f >= config.warmup) {
      run.mean_interval_ms += std::chrono::duration<double, std::milli>(now - *last_delivery).count();
      ++intervals;
    }
    last_delivery = now;
    run.idle_percent.push_back(stats.idle_percent);
    if (f >= config.warmup) {
      run.mean_idle_percent += stats.idle_percent;
      run.worst_idle_percent = std::max(run.worst_idle_percent, stats.idle_percent);
      run.mean_frame_ms += stats.frame_ms;
      for (const core::TracerFrameStats& t : stats.tracers) run.mean_rendering_tracers += t.outcome == core::TracerOutcome::rendered;
      ++counted;
    }
  };
  for (int f = 0; f < config.frames; ++f) {
    core::BandJob job;
    // Simulated tracers only need rows; real ones get a 16:9 image so the view is not a sliver.
    const int width = config.real.empty() ? config.width : std::max(config.width, config.rows * 16 / 9);
    job.camera = core::spin_camera(width, config.rows, f * step);
    // Real tracers path-trace the scene from the player start with the default frame (NEE, one
    // bounce); simulated ones read only the camera and the frame index.
    job.params = core::default_frame_params();
    job.params.frame_index = static_cast<kuint>(f);
    if (!config.real.empty()) {
      job.camera.origin[0] = eye.x;
      job.camera.origin[1] = eye.y;
      job.camera.origin[2] = eye.z;
    }
    if (config.frames_in_flight == 1) {
      take(renderer.render(job, frame));
    } else if (std::optional<core::FramePipeline::Delivered> done = pipeline.push(job)) {
      take(done->stats);
    }
  }
  if (std::optional<core::FramePipeline::Delivered> done = pipeline.drain()) take(done->stats);
  if (intervals > 0) run.mean_interval_ms /= intervals;
  if (counted > 0) {
    run.mean_idle_percent /= counted;
    run.mean_frame_ms /= counted;
    run.mean_rendering_tracers /= counted;
  }
  return run;
}

}  // namespace

std::vector<BalanceBenchRun> run_balance_bench(const BalanceBenchConfig& config) {
  if (config.speeds.empty()) throw std::invalid_argument("bench balance: no speeds");
  if (config.fixed_ms.empty()) throw std::invalid_argument("bench balance: no fixed costs");
  const std::vector<std::string> balancers = config.balancers.empty() ? balance::balancer_names() : config.balancers;
  std::vector<int> counts = config.tracer_counts;
  if (!config.real.empty()) counts = {static_cast<int>(config.real.size())};
  std::vector<BalanceBenchRun> runs;
  for (const std::string& path : config.paths) {
    for (int count : counts) {
      for (const std::string& b : balancers) runs.push_back(run_one(config, path, count, b));
    }
  }
  return runs;
}

nlohmann::json balance_bench_json(const BalanceBenchConfig& config, const std::vector<BalanceBenchRun>& runs) {
  nlohmann::json j;
  j["config"] = {{"tracer_counts", config.tracer_counts}, {"speeds", config.speeds}, {"fixed_ms", config.fixed_ms}, {"ms_per_cost", config.ms_per_cost},  {"noise", config.noise}, {"row_work", config.row_work}, {"row_work_error", config.row_work_error},
                 {"frames", config.frames},               {"warmup", config.warmup},  {"paths", config.paths},
                 {"rows", config.rows},                   {"seed", config.seed},      {"alpha", config.balancer_options.alpha},
                 {"robin_hood_units", config.balancer_options.robin_hood_units},
                 {"row_cost_rates", {config.balancer_options.cost_rate, config.balancer_options.speed_rate}},
                 {"real", config.real}, {"clock", config.clock}, {"time_scale", config.time_scale},
                 {"frames_in_flight", config.frames_in_flight},
                 {"metric", config.frames_in_flight == 1
                                ? "idle % = sum over tracers of (frame time - tracer time) / (tracers * frame time)"
                                : "idle % = sum over tracers of time without a job before the band / sum of that and band times"}};
  j["runs"] = nlohmann::json::array();
  for (const BalanceBenchRun& r : runs) {
    j["runs"].push_back({{"path", r.path},
                         {"tracers", r.tracers},
                         {"balancer", r.balancer},
                         {"mean_idle_percent", r.mean_idle_percent},
                         {"worst_idle_percent", r.worst_idle_percent},
                         {"mean_frame_ms", r.mean_frame_ms},
                         {"mean_rendering_tracers", r.mean_rendering_tracers},
                         {"mean_interval_ms", r.mean_interval_ms},
                         {"idle_percent_per_frame", r.idle_percent}});
  }
  return j;
}

std::string balance_bench_table(const std::vector<BalanceBenchRun>& runs) {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line, "%-6s %-8s %-16s %12s %12s %14s %10s %12s\n", "path", "tracers", "balancer", "mean idle %",
                "worst idle %", "mean frame ms", "rendering", "interval ms");
  out += line;
  std::string last_group;
  for (const BalanceBenchRun& r : runs) {
    const std::string group = r.path + std::to_string(r.tracers);
    if (!last_group.empty() && group != last_group) out += "\n";
    last_group = group;
    std::snprintf(line, sizeof line, "%-6s %-8d %-16s %12.2f %12.2f %14.3f %10.2f %12.3f\n", r.path.c_str(), r.tracers,
                  r.balancer.c_str(), r.mean_idle_percent, r.worst_idle_percent, r.mean_frame_ms, r.mean_rendering_tracers,
                  r.mean_interval_ms);
    out += line;
  }
  return out;
}

}  // namespace cohort::app
