// `cohort bench balance`: how much of the summed tracer time each balancer leaves idle while the camera
// spins (Brigade, Table 1), with simulated tracers of chosen speed and noise, or real ones.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cohort/balance/balancer.h"
#include "default_map.h"

namespace cohort::app {

struct BalanceBenchConfig {
  std::vector<std::string> balancers;    // empty: all
  std::vector<int> tracer_counts{2, 3, 4};
  std::vector<double> speeds{1.0};       // speed of simulated tracer i is speeds[i % size]
  std::vector<double> fixed_ms{0.0};     // fixed cost per band of simulated tracer i: fixed_ms[i % size]
  double ms_per_cost = 0.05;             // simulated ms per cost unit at speed 1 (a 720-row frame is ~860 units)
  double noise = 0.02;
  bool row_work = true;                  // simulated tracers report per-row work (the Row Cost proxy)
  double row_work_error = 0.2;
  // Simulated tracers on the virtual clock report their times; on "sleep" or "spin" they take that
  // long (times time_scale) and the renderer measures wall-clock time, threads and all.
  std::string clock = "virtual";
  double time_scale = 1.0;
  int frames = 360;
  int warmup = 5;                        // first frames left out of mean/worst (nothing measured yet)
  std::vector<std::string> paths{"slow", "fast"};
  int rows = 720, width = 32;
  uint64_t seed = 1;
  balance::BalancerOptions balancer_options;
  std::vector<std::string> real;         // real tracer names; empty: simulated
  std::string real_scene = kTestMapFile;   // what real tracers render
  // RendererOptions::frames_in_flight: 2 drives the Renderer through core::FramePipeline with frame N+1
  // handed out before N is waited for (compare the wall interval on a sleep or spin clock).
  int frames_in_flight = 1;
};

struct BalanceBenchRun {
  std::string path, balancer;
  int tracers = 0;
  double mean_idle_percent = 0.0, worst_idle_percent = 0.0;
  double mean_frame_ms = 0.0;            // slowest band per frame (what idle % cannot show: a faster frame)
  double mean_rendering_tracers = 0.0;   // tracers given rows per frame (a balancer may bench a slow one)
  double mean_interval_ms = 0.0;         // wall time between frames delivered (meaningless on the virtual clock)
  std::vector<double> idle_percent;      // per frame, warm-up included
};

// Degrees of yaw per frame for a named camera path; throws std::invalid_argument for unknown names.
double path_degrees_per_frame(const std::string& path);

std::vector<BalanceBenchRun> run_balance_bench(const BalanceBenchConfig& config);
nlohmann::json balance_bench_json(const BalanceBenchConfig& config, const std::vector<BalanceBenchRun>& runs);
std::string balance_bench_table(const std::vector<BalanceBenchRun>& runs);

}  // namespace cohort::app

namespace cohort::app {
// PNG (or PPM without OpenImageIO) chart of idle % per frame, one panel per path and tracer count,
// one line per balancer.
void write_balance_plot(const std::string& file, const std::vector<BalanceBenchRun>& runs);
}  // namespace cohort::app
