// `cohort bench devices`: does every device add speed? The same camera path rendered by each tracer
// alone and by mixes of them, with median / p95 wall ms per frame, fps, idle % and the scaling
// efficiency of each mix: (1 / T_mix) / sum over its tracers of (1 / T_alone), 1 when the mix is as
// fast as its tracers' speeds added up.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "default_map.h"

namespace cohort::app {

struct DevicesBenchConfig {
  std::vector<std::vector<std::string>> mixes;   // tracer specs per mix; empty: default_device_mixes()
  std::string scene = kTestMapFile;
  int width = 1280, height = 720;
  int frames = 60, warmup = 10;                  // the first `warmup` frames are not counted
  std::string camera_path = "spin-slow";
  std::string balancer = "whole-cost";
  // 0: frame by frame (Renderer::render: each frame handed out, waited for and merged before the next; wall
  // ms = that frame). 1 or 2: through the FramePipeline as `cohort render` runs it (without the post), the
  // next frame announced at hand-out (remote tracers' jobs ahead), with RendererOptions::frames_in_flight;
  // wall ms = the interval between delivered frames (1 / frame rate).
  int frames_in_flight = 0;
};

// A remote tracer's traffic over the counted frames (tracers/mpi): what crossed the wire per frame
// (commits and band jobs out, band rows back, headers included) and the band round trip.
struct RemoteLinkRun {
  std::string tracer;
  double sent_bytes_per_frame = 0.0, received_bytes_per_frame = 0.0;
  double mean_round_trip_ms = 0.0;  // band job sent -> rows received
  double mean_node_ms = 0.0;        // the node's own time for its band
  // Where the round trip went (tracers::MpiLinkStats): the node's tracers' render calls (GPU: kernel,
  // downloads, waits), of that what they measured themselves, the node applying commits with the job
  // waiting (in the round trip's way) and before it came (hidden: commits ahead), and rank 0's wait for
  // the band's first piece. Bands right after a full resync are left out.
  double mean_node_render_ms = 0.0, mean_node_tracer_ms = 0.0, mean_node_commit_ms = 0.0;
  double mean_node_commit_ahead_ms = 0.0;
  uint64_t commits_ahead = 0;  // commits sent behind a band's job while it rendered, over the counted frames
  double mean_first_piece_ms = 0.0;
  // The node waiting for its next job between bands (protocol 7). The bench renders frame by frame,
  // without the pipeline's announcements, so it sends no jobs ahead: this is the gap they would close.
  double mean_node_idle_ms = 0.0;
};

struct DevicesBenchRun {
  std::vector<std::string> tracers;
  double median_ms = 0.0, p95_ms = 0.0, fps = 0.0;
  double mean_idle_percent = 0.0, worst_idle_percent = 0.0;
  double mean_rendering_tracers = 0.0;  // tracers given rows per frame (a balancer may bench one)
  double efficiency = 0.0;              // scaling efficiency; 1 for a tracer alone
  std::vector<double> wall_ms;          // per counted frame (with the pipeline: the interval before it)
  std::vector<RemoteLinkRun> remote;    // one per remote tracer of the mix
};

// Every GPU alone (CUDA devices, else OpenCL accelerators, else every OpenCL device), Embree alone,
// each GPU with Embree, and all GPUs without and with Embree.
std::vector<std::vector<std::string>> default_device_mixes();

// Runs every mix, and every tracer of a mix alone first (for the efficiencies). Throws what the
// registry throws for a tracer that is not built or not present.
std::vector<DevicesBenchRun> run_devices_bench(const DevicesBenchConfig& config);
std::string devices_bench_table(const std::vector<DevicesBenchRun>& runs);
nlohmann::json devices_bench_json(const DevicesBenchConfig& config, const std::vector<DevicesBenchRun>& runs);
// Bar chart: median wall ms per mix, p95 as a whisker, efficiency and fps written beside each bar.
void write_devices_plot(const std::string& file, const std::vector<DevicesBenchRun>& runs);

}  // namespace cohort::app
