#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "balance_bench.h"
#include "cohort/core/image_output.h"
#include "raster/image.h"

namespace cohort::app {

namespace {

using raster::Rgba8;

const Rgba8 kBackground{255, 255, 255}, kInk{30, 30, 30}, kGrid{225, 225, 225};
const Rgba8 kPalette[] = {{150, 150, 150}, {230, 140, 20}, {200, 40, 40}, {40, 90, 200}, {20, 150, 60},
                        {140, 60, 170},  {0, 160, 170},  {120, 80, 40}};
constexpr int kTextScale = 2;  // font pixels drawn 2x2: labels readable on a chart this size

std::string format_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, v == std::floor(v) ? "%.0f" : "%.1f", v);
  return buf;
}

// A round axis maximum at or above v: 1, 2, 5 x 10^k.
double nice_ceiling(double v) {
  if (!(v > 0.0)) return 1.0;
  const double p = std::pow(10.0, std::floor(std::log10(v)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * p >= v) return m * p;
  return 10.0 * p;
}

}  // namespace

void write_balance_plot(const std::string& file, const std::vector<BalanceBenchRun>& runs) {
  if (runs.empty()) throw std::runtime_error("--plot " + file + ": no runs to plot");
  // Panels: one row per path, one column per tracer count, in the order the runs came.
  std::vector<std::string> paths, balancers;
  std::vector<int> counts;
  for (const BalanceBenchRun& r : runs) {
    if (std::find(paths.begin(), paths.end(), r.path) == paths.end()) paths.push_back(r.path);
    if (std::find(counts.begin(), counts.end(), r.tracers) == counts.end()) counts.push_back(r.tracers);
    if (std::find(balancers.begin(), balancers.end(), r.balancer) == balancers.end()) balancers.push_back(r.balancer);
  }
  const int panel_w = 560, panel_h = 320, margin_left = 70, margin_bottom = 50, margin_top = 34, legend_h = 40;
  const int width = static_cast<int>(counts.size()) * (panel_w + margin_left) + 20;
  const int height = legend_h + static_cast<int>(paths.size()) * (panel_h + margin_top + margin_bottom) + 10;
  raster::Image8 image;
  image.resize(width, height);
  raster::fill_rect(image, 0, 0, width, height, kBackground);
  auto text = [&](int x, int y, const std::string& s, Rgba8 c) { raster::draw_text(image, x, y, s, c, kTextScale); };
  auto text_advance = [](const std::string& s) { return raster::text_advance(s, kTextScale); };

  // Legend across the top.
  int lx = margin_left;
  for (size_t b = 0; b < balancers.size(); ++b) {
    const Rgba8 c = kPalette[b % std::size(kPalette)];
    raster::fill_rect(image, lx, 16, 24, 4, c);
    text(lx + 30, 12, balancers[b], kInk);
    lx += 30 + text_advance(balancers[b]) + 30;
  }
  text(lx + 20, 12, "(lines above a panel top are clipped)", Rgba8{110, 110, 110});

  for (size_t pi = 0; pi < paths.size(); ++pi) {
    for (size_t ci = 0; ci < counts.size(); ++ci) {
      const int x0 = static_cast<int>(ci) * (panel_w + margin_left) + margin_left;
      const int y0 = legend_h + static_cast<int>(pi) * (panel_h + margin_top + margin_bottom) + margin_top;
      std::vector<const BalanceBenchRun*> panel;
      for (const BalanceBenchRun& r : runs)
        if (r.path == paths[pi] && r.tracers == counts[ci]) panel.push_back(&r);
      if (panel.empty()) continue;
      // The y range follows the better balancers: twice the lower-third (over runs) of each run's 95th
      // percentile, so a "none" or oscillating "perfect" line far above is clipped at the top.
      std::vector<double> typical;
      size_t frames = 0;
      for (const BalanceBenchRun* r : panel) {
        std::vector<double> v = r->idle_percent;
        if (v.empty()) continue;
        std::sort(v.begin(), v.end());
        typical.push_back(v[static_cast<size_t>(0.95 * static_cast<double>(v.size() - 1))]);
        frames = std::max(frames, r->idle_percent.size());
      }
      std::sort(typical.begin(), typical.end());
      const double y_max = nice_ceiling(typical.empty() ? 1.0 : 2.0 * typical[(typical.size() - 1) / 3]);
      const std::string title = paths[pi] + " spin, " + std::to_string(counts[ci]) + " tracers: idle % per frame";
      text(x0, y0 - 24, title, kInk);
      for (int t = 0; t <= 4; ++t) {
        const int y = y0 + panel_h - t * panel_h / 4;
        raster::draw_line(image, x0, y, x0 + panel_w, y, kGrid);
        const std::string label = format_number(y_max * t / 4);
        text(x0 - 8 - text_advance(label), y - raster::text_height(kTextScale) / 2, label, kInk);
      }
      const size_t last = frames > 1 ? frames - 1 : 1;
      const double x_step = nice_ceiling(static_cast<double>(last) / 6.0);
      for (double f = 0.0; f <= static_cast<double>(last); f += x_step) {
        const int x = x0 + static_cast<int>(std::lround(f * panel_w / static_cast<double>(last)));
        const std::string label = format_number(f);
        raster::draw_line(image, x, y0 + panel_h, x, y0 + panel_h + 5, kInk);
        text(x - text_advance(label) / 2, y0 + panel_h + 10, label, kInk);
      }
      text(x0 + panel_w / 2 - text_advance("frame") / 2, y0 + panel_h + 30, "frame", kInk);
      raster::draw_text_vertical(image, x0 - 62, y0 + panel_h / 2 - text_advance("idle %") / 2, "idle %", kInk, kTextScale);
      for (const BalanceBenchRun* r : panel) {
        const size_t b = static_cast<size_t>(std::find(balancers.begin(), balancers.end(), r->balancer) - balancers.begin());
        const Rgba8 c = kPalette[b % std::size(kPalette)];
        auto px = [&](size_t i) { return x0 + static_cast<double>(i) * panel_w / last; };
        auto py = [&](double v) { return y0 + panel_h - std::clamp(v / y_max, 0.0, 1.0) * panel_h; };
        for (size_t i = 1; i < r->idle_percent.size(); ++i)
          raster::draw_line(image, px(i - 1), py(r->idle_percent[i - 1]), px(i), py(r->idle_percent[i]), c, 2);
      }
      raster::draw_line(image, x0, y0, x0, y0 + panel_h, kInk, 2);
      raster::draw_line(image, x0, y0 + panel_h, x0 + panel_w, y0 + panel_h, kInk, 2);
    }
  }
  core::write_ldr_image(file, image.width, image.height, image.rgba);
}

}  // namespace cohort::app
