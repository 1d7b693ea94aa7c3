#include "devices_bench.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <optional>
#include <stdexcept>

#include <spdlog/spdlog.h>

#include "camera_path.h"
#include "cohort/balance/order_statistics.h"
#include "cohort/core/frame_defaults.h"
#include "cohort/core/frame_pipeline.h"
#include "cohort/core/renderer.h"
#include "cohort/core/view.h"
#include "cohort/tracers/tracer_registry.h"
#include "real_tracers.h"
#ifdef COHORT_HAVE_MPI
#include "cohort/tracers/mpi_tracer.h"
#endif

namespace cohort::app {

namespace {

std::string join(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : "+") + n;
  return out;
}

DevicesBenchRun run_mix(const DevicesBenchConfig& config, const std::vector<std::string>& names) {
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "" : ",") + n;
  RealTracers real = make_real_tracers(names, config.scene);
  core::RendererOptions options;
  options.balancer = config.balancer;
#ifdef COHORT_HAVE_MPI
  // The remote tracers' link counters, read before and after the counted frames.
  std::vector<const tracers::MpiTracer*> remote;
  for (const auto& t : real.tracers)
    if (const auto* m = dynamic_cast<const tracers::MpiTracer*>(t.get())) remote.push_back(m);
  std::vector<tracers::MpiLinkStats> before(remote.size());
#endif
  if (config.frames_in_flight < 0 || config.frames_in_flight > 2)
    throw std::invalid_argument("bench devices: frames in flight must be 0 (frame by frame), 1 or 2");
  options.frames_in_flight = std::max(1, config.frames_in_flight);
  core::Renderer renderer(std::move(real.tracers), options);
  const CameraPath path = parse_camera_path(config.camera_path);
  const auto job_of_frame = [&](int f) {
    const CameraPose pose = camera_path_pose(path, real.eye, real.yaw, f);
    core::BandJob job;
    job.camera = core::make_camera(pose.origin, {pose.yaw, 0.0f}, core::kDefaultFovX, config.width, config.height);
    job.params = core::default_frame_params();
    job.params.frame_index = static_cast<kuint>(f);
    return job;
  };

  DevicesBenchRun run;
  run.tracers = names;
  int counted = 0;
  const auto take = [&](int f, const core::FrameStats& stats, double frame_ms) {
#ifdef COHORT_HAVE_MPI
    // The link counters from the delivery of the last frame not counted (with the pipeline the first counted
    // frame's job is out by then: its bytes out are left out, its rows back counted).
    if (f == config.warmup - 1)
      for (size_t i = 0; i < remote.size(); ++i) before[i] = remote[i]->link_stats();
#endif
    if (f < config.warmup) return;
    run.wall_ms.push_back(frame_ms);
    run.mean_idle_percent += stats.idle_percent;
    run.worst_idle_percent = std::max(run.worst_idle_percent, stats.idle_percent);
    for (const core::TracerFrameStats& t : stats.tracers) run.mean_rendering_tracers += t.outcome == core::TracerOutcome::rendered;
    ++counted;
  };
#ifdef COHORT_HAVE_MPI
  if (config.warmup == 0)
    for (size_t i = 0; i < remote.size(); ++i) before[i] = remote[i]->link_stats();
#endif
  if (config.frames_in_flight == 0) {
    core::FrameBuffer frame;
    for (int f = 0; f < config.frames; ++f) {
      const core::FrameStats stats = renderer.render(job_of_frame(f), frame);
      take(f, stats, stats.wall_ms);
    }
  } else {
    core::FramePipeline pipeline(renderer);
    std::optional<std::chrono::steady_clock::time_point> last_delivery;
    const auto delivered = [&](const std::optional<core::FramePipeline::Delivered>& done) {
      if (!done) return;
      const auto now = std::chrono::steady_clock::now();
      const double interval =
          last_delivery ? std::chrono::duration<double, std::milli>(now - *last_delivery).count() : done->stats.wall_ms;
      last_delivery = now;
      take(static_cast<int>(done->job.params.frame_index), done->stats, interval);
    };
    for (int f = 0; f < config.frames; ++f) {
      delivered(pipeline.push(job_of_frame(f), {}, [&]() -> std::optional<core::BandJob> {
        if (f + 1 < config.frames) return job_of_frame(f + 1);
        return std::nullopt;
      }));
    }
    delivered(pipeline.drain());
  }
  if (counted == 0) throw std::invalid_argument("bench devices: --frames must exceed --warmup");
#ifdef COHORT_HAVE_MPI
  for (size_t i = 0; i < remote.size(); ++i) {
    const tracers::MpiLinkStats after = remote[i]->link_stats();
    RemoteLinkRun link;
    link.tracer = remote[i]->name();
    link.sent_bytes_per_frame = double(after.bytes_sent - before[i].bytes_sent) / counted;
    link.received_bytes_per_frame = double(after.bytes_received - before[i].bytes_received) / counted;
    const uint64_t bands = after.steady_bands - before[i].steady_bands;  // not the first after a full resync
    if (bands > 0) {
      link.mean_round_trip_ms = (after.total_round_trip_ms - before[i].total_round_trip_ms) / double(bands);
      link.mean_node_ms = (after.total_node_ms - before[i].total_node_ms) / double(bands);
      link.mean_node_render_ms = (after.total_node_render_ms - before[i].total_node_render_ms) / double(bands);
      link.mean_node_tracer_ms = (after.total_node_tracer_ms - before[i].total_node_tracer_ms) / double(bands);
      link.mean_node_commit_ms = (after.total_node_commit_ms - before[i].total_node_commit_ms) / double(bands);
      link.mean_node_commit_ahead_ms =
          (after.total_node_commit_ahead_ms - before[i].total_node_commit_ahead_ms) / double(bands);
      link.commits_ahead = after.commits_ahead - before[i].commits_ahead;
      link.mean_first_piece_ms = (after.total_first_piece_ms - before[i].total_first_piece_ms) / double(bands);
      link.mean_node_idle_ms = (after.total_node_idle_ms - before[i].total_node_idle_ms) / double(bands);
    }
    run.remote.push_back(link);
  }
#endif
  run.mean_idle_percent /= counted;
  run.mean_rendering_tracers /= counted;
  run.median_ms = median(run.wall_ms);
  run.p95_ms = quantile(run.wall_ms, 0.95);
  run.fps = run.median_ms > 0.0 ? 1000.0 / run.median_ms : 0.0;
  spdlog::info("bench devices: {}: median {:.3f} ms, p95 {:.3f} ms, mean idle {:.2f} %", join(names), run.median_ms,
               run.p95_ms, run.mean_idle_percent);
  return run;
}

}  // namespace

std::vector<std::vector<std::string>> default_device_mixes() {
  std::vector<std::string> gpus;
  for (const tracers::TracerSpec& s : tracers::parse_tracer_list("all"))
    if (s.kind != "embree") gpus.push_back(s.text);
  if (gpus.empty() && tracers::device_count("opencl") > 0)
    for (const tracers::TracerSpec& s : tracers::parse_tracer_list("opencl:all")) gpus.push_back(s.text);
  const bool embree = tracers::device_count("embree") > 0;
  std::vector<std::vector<std::string>> mixes;
  if (embree) mixes.push_back({"embree"});
  for (const std::string& g : gpus) mixes.push_back({g});
  if (embree)
    for (const std::string& g : gpus) mixes.push_back({"embree", g});
  if (gpus.size() > 1) {
    mixes.push_back(gpus);
    if (embree) {
      std::vector<std::string> all{"embree"};
      all.insert(all.end(), gpus.begin(), gpus.end());
      mixes.push_back(all);
    }
  }
  if (mixes.empty()) throw std::runtime_error("bench devices: no tracer can run on this machine");
  return mixes;
}

std::vector<DevicesBenchRun> run_devices_bench(const DevicesBenchConfig& config) {
  const std::vector<std::vector<std::string>> mixes = config.mixes.empty() ? default_device_mixes() : config.mixes;
  // Each tracer alone first: the efficiencies need its time.
  std::map<std::string, double> alone_ms;
  std::vector<DevicesBenchRun> runs;
  auto already = [&](const std::vector<std::string>& mix) {
    return std::any_of(runs.begin(), runs.end(), [&](const DevicesBenchRun& r) { return r.tracers == mix; });
  };
  for (const auto& mix : mixes) {
    for (const std::string& name : mix) {
      if (alone_ms.count(name)) continue;
      runs.push_back(run_mix(config, {name}));
      alone_ms[name] = runs.back().median_ms;
    }
  }
  for (const auto& mix : mixes)
    if (!already(mix)) runs.push_back(run_mix(config, mix));
  for (DevicesBenchRun& r : runs) {
    double summed_speed = 0.0;
    for (const std::string& name : r.tracers) summed_speed += 1.0 / alone_ms.at(name);
    r.efficiency = r.median_ms > 0.0 && summed_speed > 0.0 ? (1.0 / r.median_ms) / summed_speed : 0.0;
  }
  return runs;
}

std::string devices_bench_table(const std::vector<DevicesBenchRun>& runs) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "%-36s %10s %10s %9s %11s %12s %10s %11s\n", "tracers", "median ms", "p95 ms", "fps",
                "mean idle %", "worst idle %", "rendering", "efficiency");
  out += line;
  for (const DevicesBenchRun& r : runs) {
    std::snprintf(line, sizeof line, "%-36s %10.3f %10.3f %9.1f %11.2f %12.2f %10.2f %10.1f%%\n", join(r.tracers).c_str(),
                  r.median_ms, r.p95_ms, r.fps, r.mean_idle_percent, r.worst_idle_percent, r.mean_rendering_tracers,
                  100.0 * r.efficiency);
    out += line;
  }
  bool any_remote = false;
  for (const DevicesBenchRun& r : runs) any_remote = any_remote || !r.remote.empty();
  if (!any_remote) return out;
  std::snprintf(line, sizeof line, "\n%-36s %-10s %14s %14s %15s %12s\n", "remote tracers (per counted frame)", "tracer",
                "sent bytes", "received bytes", "round trip ms", "node ms");
  out += line;
  for (const DevicesBenchRun& r : runs)
    for (const RemoteLinkRun& l : r.remote) {
      std::snprintf(line, sizeof line, "%-36s %-10s %14.0f %14.0f %15.3f %12.3f\n", join(r.tracers).c_str(),
                    l.tracer.c_str(), l.sent_bytes_per_frame, l.received_bytes_per_frame, l.mean_round_trip_ms,
                    l.mean_node_ms);
      out += line;
    }
  return out;
}

namespace {
nlohmann::json remote_json(const std::vector<RemoteLinkRun>& links) {
  nlohmann::json out = nlohmann::json::array();
  for (const RemoteLinkRun& l : links)
    out.push_back({{"tracer", l.tracer},
                   {"sent_bytes_per_frame", l.sent_bytes_per_frame},
                   {"received_bytes_per_frame", l.received_bytes_per_frame},
                   {"mean_round_trip_ms", l.mean_round_trip_ms},
                   {"mean_node_ms", l.mean_node_ms},
                   {"mean_node_render_ms", l.mean_node_render_ms},
                   {"mean_node_tracer_ms", l.mean_node_tracer_ms},
                   {"mean_node_commit_ms", l.mean_node_commit_ms},
                   {"mean_node_commit_ahead_ms", l.mean_node_commit_ahead_ms},
                   {"commits_ahead", l.commits_ahead},
                   {"mean_first_piece_ms", l.mean_first_piece_ms},
                   {"mean_node_idle_ms", l.mean_node_idle_ms}});
  return out;
}
}  // namespace

nlohmann::json devices_bench_json(const DevicesBenchConfig& config, const std::vector<DevicesBenchRun>& runs) {
  nlohmann::json j;
  j["config"] = {{"scene", config.scene},   {"width", config.width},         {"height", config.height},
                 {"frames", config.frames}, {"warmup", config.warmup},       {"camera_path", config.camera_path},
                 {"balancer", config.balancer}, {"frames_in_flight", config.frames_in_flight},
                 {"metric", config.frames_in_flight == 0
                                ? "wall ms = Renderer frame (bands, merge, recovery); efficiency = (1/T_mix) / sum(1/T_alone)"
                                : "wall ms = interval between frames delivered by the FramePipeline (bands, merge, "
                                  "recovery, overlapped); efficiency = (1/T_mix) / sum(1/T_alone)"}};
  j["runs"] = nlohmann::json::array();
  for (const DevicesBenchRun& r : runs) {
    j["runs"].push_back({{"tracers", r.tracers},
                         {"median_ms", r.median_ms},
                         {"p95_ms", r.p95_ms},
                         {"fps", r.fps},
                         {"mean_idle_percent", r.mean_idle_percent},
                         {"worst_idle_percent", r.worst_idle_percent},
                         {"mean_rendering_tracers", r.mean_rendering_tracers},
                         {"efficiency", r.efficiency},
                         {"wall_ms", r.wall_ms},
                         {"remote", remote_json(r.remote)}});
  }
  return j;
}

}  // namespace cohort::app
