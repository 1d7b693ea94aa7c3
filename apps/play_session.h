// A live session on a map: the loaded scene in a RenderWorld, the test-map scenario driving it, the
// core's world sync turning each frame's changes into commit buffers, the Renderer splitting rows
// over the tracers, adaptive convergence and the tone mapper. `cohort play` draws its frames in a
// window; the session itself needs no display.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cohort/core/atrous_filter.h"
#include "cohort/core/frame_buffer.h"
#include "cohort/core/frame_defaults.h"
#include "cohort/core/frame_stats.h"
#include "cohort/core/upsample.h"
#include "cohort/kernel/layout.h"
#include "viewer/fly_camera.h"

namespace cohort::app {

struct SessionOptions {
  std::string map;
  std::vector<std::string> bases;
  std::string tracers;              // empty: "all" (parse_tracer_list: Embree plus every GPU once)
  std::string balancer = "whole-cost";  // benches a tracer that would slow the frame (docs/balancing.md)
  bool scenario = true;
  // The a-trous filter after the reprojection: "atrous", "none", or "auto" (atrous where the
  // post-processing runs on a CUDA GPU, where it costs 1-3 ms; none on the host, where it would set the
  // frame rate). Passes as `cohort render` picks them for the window's height. "oidn" / "oidn-cuda": Open
  // Image Denoise on the CPU / an NVIDIA GPU after the accumulation instead (core/oidn_denoiser.h), at
  // denoise_quality.
  std::string denoise = "auto";
  std::string denoise_quality = "balanced";
  // Frames of history below which the a-trous filter's history fix blurs a pixel wider (0: off).
  float history_fix = core::AtrousOptions{}.history_fix_frames;
  // Where the G-buffer comes from: "centre" (a ray of its own through each pixel's centre) or "first-hit"
  // (the first sample's own first surface: no extra ray; kernel/aux_outputs.h).
  std::string aux_rays = "auto";
  // What the tracers hand back (core::BandFormat's names): RGB9E5 by default (4 bytes a pixel, docs/cluster.md).
  std::string band_format = "rgb9e5";
  // RendererOptions::frames_in_flight: 2 hands the next frame out before the one before is back (a frame more
  // between input and image where the tracers set the pace; docs/balancing.md, "Two frames in flight").
  int frames_in_flight = 1;
  // Rank 0's port for nodes that join (docs/cluster.md): the file it writes, and how long the remote
  // tracers wait for their first nodes (empty file: no port).
  std::string node_port_file;
  double node_wait_s = 0.0;
  int window_height = 360;
};

struct FrameSettings {
  int width = 640, height = 360;
  int spp = 1;
  kuint mode = K_MODE_PATH;
  int max_bounces = 1;
  kuint light_sampling = core::default_frame_params().light_sampling;
  std::string tone_curve = "aces";
  bool reproject = false;           // per-pixel reprojection (core/reprojection.h) instead of Brigade's blend
  bool accumulate = true;           // false: each frame as rendered (--convergence none), neither of the two
  // Dynamic resolution (core/upsample.h): below 1 with joint_bilateral or nearest, width x height is the
  // window's and paths are traced for about render_scale^2 of its pixels, the rest reconstructed from the
  // G-buffer; with bilinear the caller passes the smaller size and the window stretches it.
  double render_scale = 1.0;
  core::UpsampleMethod upsample = core::UpsampleMethod::bilinear;
};

struct SessionFrame {
  bool ready = false;               // false for the first call: its frame comes back with the next one
  core::FrameStats stats;
  size_t commit_bytes = 0;
  std::vector<uint8_t> display;     // tone-mapped RGBA8 of the converged image
  int width = 0, height = 0;
};

class PlaySession {
 public:
  // Loads the map and starts the tracers; throws std::runtime_error (or scene::ParseError) with the
  // reason when the map cannot be used or no tracer starts. Tracers that fail are listed in warnings().
  explicit PlaySession(const SessionOptions& options);
  ~PlaySession();

  // Advance the scenario by `seconds` (unless paused), put the flashlight on the camera, sync the
  // world to the tracers and hand the frame to them; returns the frame handed out by the previous
  // call, blended and tone-mapped while this one renders (one frame of latency; the first call
  // returns no image).
  SessionFrame frame(const viewer::FlyCamera& camera, double seconds, const FrameSettings& settings);

  // Where the map's player starts, at eye height, looking along its yaw.
  viewer::FlyCamera start_camera() const;
  void set_balancer(const std::string& name);
  const std::string& balancer() const;
  bool scenario_running() const;
  bool scenario_paused() const { return paused_; }
  void set_scenario_paused(bool paused) { paused_ = paused; }
  std::vector<std::string> tracer_names() const;
  // Whether any of the session's tracers renders on a GPU (see convergence_choice.h).
  bool any_gpu_tracer() const;
  // Where the reprojection runs: "host" or "cuda:N" (the first CUDA tracer's GPU).
  const std::string& frame_post_place() const;
  bool denoising() const;  // whether the reprojected frame also goes through the a-trous filter
  // "oidn on cpu", "oidn on cuda" where Open Image Denoise filters every shown frame, else empty.
  const std::string& oidn_label() const;
  // Tracers that did not start, a scenario that cannot run: things the HUD and log should say.
  const std::vector<std::string>& warnings() const { return warnings_; }
  const std::string& map_name() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
  bool paused_ = false;
  std::vector<std::string> warnings_;
};

// "path", "direct", ... in K_MODE_* order.
const std::vector<std::string>& debug_mode_names();
std::optional<kuint> debug_mode_from_name(const std::string& name);
const std::vector<std::string>& tone_curve_names();

}  // namespace cohort::app
