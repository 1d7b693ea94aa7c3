#include "hud.h"

#include <algorithm>
#include <cstdio>

#include "raster/font.h"

namespace cohort::viewer {
namespace {

template <typename... Args>
std::string format(const char* fmt, Args... args) {
  char buf[256];
  std::snprintf(buf, sizeof(buf), fmt, args...);
  return buf;
}

}  // namespace

std::string format_bytes(uint64_t bytes) {
  if (bytes < 1024) return format("%llu B", static_cast<unsigned long long>(bytes));
  if (bytes < 1024 * 1024) return format("%.1f KB", bytes / 1024.0);
  return format("%.2f MB", bytes / (1024.0 * 1024.0));
}

std::vector<std::string> hud_lines(const HudState& s) {
  std::vector<std::string> lines;
  if (s.stats) {
    lines.push_back(format("FPS %.1f  FRAME %.1f MS  WALL %.1f MS", s.fps, s.stats->frame_ms, s.stats->wall_ms));
  } else {
    lines.push_back(format("FPS %.1f  NO FRAME RENDERED", s.fps));
  }
  lines.push_back(format("MODE %s  SPP %d  SCALE %.2f (%dX%d)  TONE %s", s.mode.c_str(), s.spp, s.render_scale,
                         s.render_width, s.render_height, s.tone_mapper.c_str()));
  if (s.render_scale < 1.0f && !s.upsample.empty()) lines.back() += "  UPSAMPLE " + s.upsample;
  if (s.target_fps > 0)
    lines.back() += format("  AUTO %d FPS", s.target_fps);
  if (s.stats) {
    lines.push_back(format("BALANCER %s  IDLE %.1f%%  CONV F %.2f  COMMIT %s", s.balancer.c_str(),
                           s.stats->idle_percent, s.stats->convergence_f, format_bytes(s.commit_bytes).c_str()));
    if (!s.accumulation.empty()) lines.back() += "  " + s.accumulation;
    for (const core::TracerFrameStats& t : s.stats->tracers) {
      std::string line = format("%-10.10s ROWS %4d-%-4d %6.1f MS", t.name.c_str(), t.row_begin, t.row_end, t.ms);
      if (t.outcome != core::TracerOutcome::rendered) line += std::string("  ") + core::to_string(t.outcome);
      if (t.recovery_rows > 0) line += format("  +%d ROWS RECOVERED", t.recovery_rows);
      lines.push_back(line);
    }
  } else {
    lines.push_back(format("BALANCER %s  COMMIT %s", s.balancer.c_str(), format_bytes(s.commit_bytes).c_str()));
  }
  lines.push_back(format("POS %.0f %.0f %.0f  YAW %.0f PITCH %.0f  SPEED %.0f  SCENARIO %s", s.camera[0], s.camera[1],
                         s.camera[2], s.yaw, s.pitch, s.speed,
                         !s.scenario_running ? "OFF" : (s.scenario_paused ? "PAUSED" : "RUNNING")));
  for (const std::string& n : s.notices) lines.push_back(n);
  return lines;
}

raster::Rgba8 stage_color(const std::string& stage) {
  if (stage.rfind("apply", 0) == 0) return {240, 150, 40, 255};
  if (stage == "render") return {70, 200, 90, 255};
  if (stage == "re-render") return {230, 60, 60, 255};
  if (stage == "world sync") return {170, 110, 230, 255};
  if (stage == "convergence") return {60, 200, 220, 255};
  if (stage == "tone map") return {235, 220, 70, 255};
  return {90, 140, 240, 255};  // balance, merge and anything else the core does
}

namespace {

// One bar per track at (x, y), `width` pixels for the frame's span; returns the height used.
int draw_timeline(raster::Image8& layer, const core::FrameStats& stats, int x, int y, int width, int scale) {
  std::vector<std::string> tracks{core::kCoreTrack};
  for (const core::TracerFrameStats& t : stats.tracers) tracks.push_back(core::tracer_track(t.id, t.name));
  double end = stats.start_ms;
  for (const core::StageSpan& s : stats.stages)
    if (s.stage != "frame") end = std::max(end, s.start_ms + s.ms);
  const double span = std::max(end - stats.start_ms, 1e-3);
  const int label = 11 * raster::kGlyphAdvance * scale;
  const int bar = 5 * scale, row_height = raster::kLineAdvance * scale + 3 * scale, pad = 3 * scale;
  raster::fill_rect(layer, x - pad, y - pad, label + width + 2 * pad,
                    static_cast<int>(tracks.size()) * row_height + pad, {0, 0, 0, 150});
  for (size_t row = 0; row < tracks.size(); ++row) {
    const int top = y + static_cast<int>(row) * row_height;
    raster::draw_text(layer, x, top, tracks[row].substr(0, 10), {200, 205, 210, 255}, scale);
    raster::fill_rect(layer, x + label, top, width, bar, {40, 40, 40, 200});
    for (const core::StageSpan& s : stats.stages) {
      if (s.track != tracks[row] || s.stage == "frame") continue;
      const int left = static_cast<int>((s.start_ms - stats.start_ms) / span * width);
      const int right = static_cast<int>((s.start_ms + s.ms - stats.start_ms) / span * width);
      raster::fill_rect(layer, x + label + left, top, std::max(right - left, 1), bar, stage_color(s.stage));
    }
  }
  return static_cast<int>(tracks.size()) * row_height;
}

// Where draw_hud puts things, so that the layer can be just as large as what it holds.
struct HudLayout {
  std::vector<std::string> lines;
  int pad = 0, box_width = 0, box_height = 0;
  int timeline_top = 0, timeline_width = 0, timeline_tracks = 0;
  int width = 0, height = 0;
};

HudLayout hud_layout(const HudState& state, int scale) {
  HudLayout l;
  l.lines = hud_lines(state);
  int widest = 0;
  for (const std::string& line : l.lines) widest = std::max(widest, raster::text_width(line, scale));
  l.pad = 3 * scale;
  l.box_width = widest + 2 * l.pad;
  l.box_height = static_cast<int>(l.lines.size()) * raster::kLineAdvance * scale + 2 * l.pad - 2 * scale;
  l.width = l.box_width;
  l.height = l.box_height;
  if (state.stats && !state.stats->stages.empty()) {
    l.timeline_top = static_cast<int>(l.lines.size()) * raster::kLineAdvance * scale + 3 * l.pad;
    l.timeline_width = 160 * scale;
    l.timeline_tracks = 1 + static_cast<int>(state.stats->tracers.size());
    // draw_timeline's box: from pad left of the labels to pad right of the bars, one row per track.
    const int label = 11 * raster::kGlyphAdvance * scale;
    const int row_height = raster::kLineAdvance * scale + 3 * scale;
    l.width = std::max(l.width, l.pad + label + l.timeline_width + l.pad);
    l.height = std::max(l.height, l.timeline_top + l.timeline_tracks * row_height);
  }
  return l;
}

}  // namespace

HudExtent hud_extent(const HudState& state, int scale) {
  const HudLayout l = hud_layout(state, scale);
  return {l.width, l.height};
}

void draw_hud(raster::Image8& layer, const HudState& state, int scale) {
  layer.clear();
  const HudLayout l = hud_layout(state, scale);
  const size_t notice_start = l.lines.size() - state.notices.size();
  raster::fill_rect(layer, 0, 0, l.box_width, l.box_height, raster::Rgba8{0, 0, 0, 150});
  for (size_t i = 0; i < l.lines.size(); ++i) {
    const raster::Rgba8 color = i >= notice_start ? raster::Rgba8{255, 220, 60, 255} : raster::Rgba8{230, 235, 240, 255};
    raster::draw_text(layer, l.pad, l.pad + static_cast<int>(i) * raster::kLineAdvance * scale, l.lines[i], color,
                      scale);
  }
  if (l.timeline_tracks > 0) draw_timeline(layer, *state.stats, l.pad, l.timeline_top, l.timeline_width, scale);
}

}  // namespace cohort::viewer
