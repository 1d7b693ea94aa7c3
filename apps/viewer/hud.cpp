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
  if (s.stats) {
    lines.push_back(format("BALANCER %s  IDLE %.1f%%  CONV F %.2f  COMMIT %s", s.balancer.c_str(),
                           s.stats->idle_percent, s.stats->convergence_f, format_bytes(s.commit_bytes).c_str()));
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

void draw_hud(raster::Image8& layer, const HudState& state, int scale) {
  layer.clear();
  const std::vector<std::string> lines = hud_lines(state);
  const size_t notice_start = lines.size() - state.notices.size();
  int widest = 0;
  for (const std::string& l : lines) widest = std::max(widest, raster::text_width(l, scale));
  const int pad = 3 * scale;
  raster::fill_rect(layer, 0, 0, widest + 2 * pad,
                    static_cast<int>(lines.size()) * raster::kLineAdvance * scale + 2 * pad - 2 * scale,
                    raster::Rgba8{0, 0, 0, 150});
  for (size_t i = 0; i < lines.size(); ++i) {
    const raster::Rgba8 color = i >= notice_start ? raster::Rgba8{255, 220, 60, 255} : raster::Rgba8{230, 235, 240, 255};
    raster::draw_text(layer, pad, pad + static_cast<int>(i) * raster::kLineAdvance * scale, lines[i], color, scale);
  }
}

}  // namespace cohort::viewer
