#include "scaling_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "cohort/core/image_output.h"
#include "raster/chart.h"
#include "raster/image.h"

namespace cohort::bench {
namespace {

using raster::Rgba8;
using namespace raster::chart;

const Rgba8 kPalette[] = {{40, 90, 200}, {230, 140, 20}, {200, 40, 40}, {20, 150, 60}, {140, 60, 170}, {0, 160, 170}};

}  // namespace

void write_scaling_plot(const std::string& file, const std::string& title, const std::string& x_label,
                        const std::string& y_label, const std::vector<ScalingSeries>& series) {
  double x_min = 1e300, x_max = 0.0, y_max = 0.0;
  for (const ScalingSeries& s : series)
    for (auto [x, y] : s.points) {
      if (!(x > 0.0)) throw std::runtime_error("scaling plot " + file + ": x must be positive (log axis)");
      x_min = std::min(x_min, x), x_max = std::max(x_max, x), y_max = std::max(y_max, y);
    }
  if (x_max <= 0.0) throw std::runtime_error("scaling plot " + file + ": no points to plot");
  y_max = nice_ceiling(y_max * 1.05);
  const double lx_min = std::log2(x_min), lx_span = std::max(1e-9, std::log2(x_max) - lx_min);

  const int panel_w = 720, panel_h = 400, margin_left = 90, margin_top = 70, margin_bottom = 60, legend_w = 260;
  const int width = margin_left + panel_w + legend_w, height = margin_top + panel_h + margin_bottom;
  raster::Image8 image;
  image.resize(width, height);
  raster::fill_rect(image, 0, 0, width, height, kBackground);
  auto text = [&](int x, int y, const std::string& s, Rgba8 c) { raster::draw_text(image, x, y, s, c, kTextScale); };
  auto advance = [](const std::string& s) { return raster::text_advance(s, kTextScale); };
  const int x0 = margin_left, y0 = margin_top;
  auto px = [&](double x) { return x0 + (std::log2(x) - lx_min) / lx_span * panel_w; };
  auto py = [&](double y) { return y0 + panel_h - std::clamp(y / y_max, 0.0, 1.0) * panel_h; };

  text(x0, 20, title, kInk);
  for (int t = 0; t <= 4; ++t) {
    const int y = y0 + panel_h - t * panel_h / 4;
    raster::draw_line(image, x0, y, x0 + panel_w, y, kGrid);
    const std::string label = format_number(y_max * t / 4);
    text(x0 - 8 - advance(label), y - raster::text_height(kTextScale) / 2, label, kInk);
  }
  std::vector<double> xs;
  for (const ScalingSeries& s : series)
    for (auto [x, y] : s.points)
      if (std::find(xs.begin(), xs.end(), x) == xs.end()) xs.push_back(x);
  for (double x : xs) {
    const double sx = px(x);
    raster::draw_line(image, sx, y0, sx, y0 + panel_h, kGrid);
    const std::string label = format_number(x);
    text(int(sx) - advance(label) / 2, y0 + panel_h + 10, label, kInk);
  }
  text(x0 + panel_w / 2 - advance(x_label) / 2, y0 + panel_h + 34, x_label, kInk);
  raster::draw_text_vertical(image, 14, y0 + panel_h / 2 - advance(y_label) / 2, y_label, kInk, kTextScale);
  for (size_t i = 0; i < series.size(); ++i) {
    const Rgba8 c = kPalette[i % std::size(kPalette)];
    const auto& pts = series[i].points;
    for (size_t k = 0; k < pts.size(); ++k) {
      raster::fill_rect(image, int(px(pts[k].first)) - 3, int(py(pts[k].second)) - 3, 7, 7, c);
      if (k > 0) raster::draw_line(image, px(pts[k - 1].first), py(pts[k - 1].second), px(pts[k].first),
                                   py(pts[k].second), c, 2);
    }
    const int ly = y0 + 10 + int(i) * 28;
    raster::fill_rect(image, x0 + panel_w + 20, ly + 6, 24, 4, c);
    text(x0 + panel_w + 50, ly, series[i].label, kInk);
  }
  raster::draw_line(image, x0, y0, x0, y0 + panel_h, kInk, 2);
  raster::draw_line(image, x0, y0 + panel_h, x0 + panel_w, y0 + panel_h, kInk, 2);
  core::write_ldr_image(file, image.width, image.height, image.rgba);
}

}  // namespace cohort::bench
