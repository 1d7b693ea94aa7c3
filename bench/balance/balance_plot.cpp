#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "balance_bench.h"
#include "cohort/core/image_output.h"
#include "devices_bench.h"
#include "raster/chart.h"
#include "raster/image.h"

namespace cohort::app {

namespace {

using raster::Rgba8;
using namespace raster::chart;

const Rgba8 kPalette[] = {{150, 150, 150}, {230, 140, 20}, {200, 40, 40}, {40, 90, 200}, {20, 150, 60},
                        {140, 60, 170},  {0, 160, 170},  {120, 80, 40}};

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

void write_devices_plot(const std::string& file, const std::vector<DevicesBenchRun>& runs) {
  if (runs.empty()) throw std::runtime_error("--plot " + file + ": no runs to plot");
  // One horizontal bar per mix (its name to the left): median wall ms, p95 as a whisker, and fps and
  // scaling efficiency written after it. Colour by the number of tracers in the mix.
  std::vector<std::string> labels;
  int label_w = 0;
  double x_max = 0.0;
  for (const DevicesBenchRun& r : runs) {
    std::string label;
    for (const std::string& t : r.tracers) label += (label.empty() ? "" : "+") + t;
    labels.push_back(label);
    label_w = std::max(label_w, raster::text_advance(label, kTextScale));
    x_max = std::max(x_max, r.p95_ms);
  }
  x_max = nice_ceiling(x_max);
  const int bar_h = 22, row_h = 36, margin_top = 60, margin_bottom = 50, bar_w = 640, note_w = 380;
  const int x0 = label_w + 30, width = x0 + bar_w + note_w, height = margin_top + static_cast<int>(runs.size()) * row_h + margin_bottom;
  raster::Image8 image;
  image.resize(width, height);
  raster::fill_rect(image, 0, 0, width, height, kBackground);
  auto text = [&](int x, int y, const std::string& str, Rgba8 c) { raster::draw_text(image, x, y, str, c, kTextScale); };
  text(x0, 14, "median wall ms per frame (whisker: p95); fps, scaling efficiency", kInk);
  const int y_axis = margin_top + static_cast<int>(runs.size()) * row_h;
  for (int t = 0; t <= 4; ++t) {
    const int x = x0 + t * bar_w / 4;
    raster::draw_line(image, x, margin_top - 6, x, y_axis, kGrid);
    const std::string label = format_number(x_max * t / 4);
    text(x - raster::text_advance(label, kTextScale) / 2, y_axis + 10, label, kInk);
  }
  text(x0 + bar_w / 2 - raster::text_advance("ms", kTextScale) / 2, y_axis + 30, "ms", kInk);
  auto px = [&](double ms) { return x0 + static_cast<int>(std::lround(std::clamp(ms / x_max, 0.0, 1.0) * bar_w)); };
  for (size_t i = 0; i < runs.size(); ++i) {
    const DevicesBenchRun& r = runs[i];
    const int y = margin_top + static_cast<int>(i) * row_h;
    const Rgba8 c = kPalette[(r.tracers.size() + 1) % std::size(kPalette)];
    text(x0 - 12 - raster::text_advance(labels[i], kTextScale), y + bar_h / 2 - raster::text_height(kTextScale) / 2, labels[i], kInk);
    raster::fill_rect(image, x0, y, std::max(px(r.median_ms) - x0, 1), bar_h, c);
    raster::draw_line(image, px(r.median_ms), y + bar_h / 2, px(r.p95_ms), y + bar_h / 2, kInk, 2);
    raster::draw_line(image, px(r.p95_ms), y + 4, px(r.p95_ms), y + bar_h - 4, kInk, 2);
    char note[96];
    std::snprintf(note, sizeof note, "%.2f ms  %.0f fps  eff %.0f%%", r.median_ms, r.fps, 100.0 * r.efficiency);
    text(x0 + bar_w + 14, y + bar_h / 2 - raster::text_height(kTextScale) / 2, note, kInk);
  }
  raster::draw_line(image, x0, margin_top - 6, x0, y_axis, kInk, 2);
  raster::draw_line(image, x0, y_axis, x0 + bar_w, y_axis, kInk, 2);
  core::write_ldr_image(file, image.width, image.height, image.rgba);
}

}  // namespace cohort::app
