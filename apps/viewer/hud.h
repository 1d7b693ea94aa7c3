// The viewer's heads-up display: what the frame cost and what the keys have set, as text lines drawn
// with the bitmap font onto a transparent RGBA8 layer that is composited over the frame.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cohort/core/frame_stats.h"
#include "raster/image.h"

namespace cohort::viewer {

struct HudState {
  double fps = 0.0;
  std::optional<core::FrameStats> stats;  // none before the first frame or when nothing renders
  std::string mode;                       // debug mode name
  int spp = 1;
  float render_scale = 1.0f;
  int render_width = 0, render_height = 0;
  std::string upsample;                   // how a scale below 1 reaches the window, e.g. "JOINT-BILATERAL"
  int target_fps = 0;                     // > 0: spp and scale are chosen to hold this frame rate
  std::string tone_mapper;
  std::string balancer;
  std::string accumulation;               // how frames accumulate, e.g. "REPROJECT+ATROUS ON cuda:0", "BRIGADE"
  uint64_t commit_bytes = 0;              // bytes of the commit sent this frame
  bool scenario_paused = false;
  bool scenario_running = false;
  float camera[3] = {0, 0, 0};
  float yaw = 0, pitch = 0, speed = 0;
  std::vector<std::string> notices;       // warnings and transient messages, drawn in yellow
};

// The text, one line per entry; per-tracer rows come from stats.
std::vector<std::string> hud_lines(const HudState& state);
std::string format_bytes(uint64_t bytes);

// The colour a timeline stage is drawn in; the legend under the bars names them.
raster::Rgba8 stage_color(const std::string& stage);

// The top-left box draw_hud draws into: everything outside it stays transparent, so the layer need
// not be larger (a window-sized layer costs a full-window blend per frame under software GL).
struct HudExtent {
  int width = 0, height = 0;
};
HudExtent hud_extent(const HudState& state, int scale = 1);

// Draw onto `layer` (cleared first): a translucent box with the lines, top-left, and under it the
// last frame's timeline: a bar per track (the core, then each tracer) with its stages along a shared
// time axis, so a tracer that waits or a serial core stage shows at a glance.
void draw_hud(raster::Image8& layer, const HudState& state, int scale = 1);

}  // namespace cohort::viewer
