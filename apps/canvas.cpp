#include "canvas.h"

#include <algorithm>
#include <cmath>

#include "raster_font.h"

namespace cohort::app {

Canvas::Canvas(int width, int height, Rgb background) : width_(width), height_(height), pixels_(static_cast<size_t>(width) * height * 4) {
  fill_rect(0, 0, width, height, background);
}

void Canvas::put(int x, int y, Rgb c) {
  if (x < 0 || y < 0 || x >= width_ || y >= height_) return;
  uint8_t* p = pixels_.data() + (static_cast<size_t>(y) * width_ + x) * 4;
  p[0] = c.r;
  p[1] = c.g;
  p[2] = c.b;
  p[3] = 255;
}

void Canvas::fill_rect(int x0, int y0, int x1, int y1, Rgb c) {
  for (int y = std::max(y0, 0); y < std::min(y1, height_); ++y)
    for (int x = std::max(x0, 0); x < std::min(x1, width_); ++x) put(x, y, c);
}

void Canvas::line(double x0, double y0, double x1, double y1, Rgb c, int thickness) {
  const double length = std::max(std::abs(x1 - x0), std::abs(y1 - y0));
  const int steps = std::max(1, static_cast<int>(std::ceil(length * 2.0)));
  const int lo = -(thickness - 1) / 2, hi = thickness / 2;
  for (int i = 0; i <= steps; ++i) {
    const double t = static_cast<double>(i) / steps;
    const int x = static_cast<int>(std::lround(x0 + (x1 - x0) * t)), y = static_cast<int>(std::lround(y0 + (y1 - y0) * t));
    for (int dy = lo; dy <= hi; ++dy)
      for (int dx = lo; dx <= hi; ++dx) put(x + dx, y + dy, c);
  }
}

int Canvas::text_width(const std::string& s, int scale) { return static_cast<int>(s.size()) * (kGlyphWidth + 1) * scale; }
int Canvas::text_height(int scale) { return kGlyphHeight * scale; }

void Canvas::text(int x, int y, const std::string& s, Rgb c, int scale) {
  for (size_t i = 0; i < s.size(); ++i) {
    const auto g = glyph(s[i]);
    const int ox = x + static_cast<int>(i) * (kGlyphWidth + 1) * scale;
    for (int row = 0; row < kGlyphHeight; ++row)
      for (int col = 0; col < kGlyphWidth; ++col)
        if (g[static_cast<size_t>(row)] & (1 << (kGlyphWidth - 1 - col)))
          fill_rect(ox + col * scale, y + row * scale, ox + (col + 1) * scale, y + (row + 1) * scale, c);
  }
}

void Canvas::text_vertical(int x, int y, const std::string& s, Rgb c, int scale) {
  const int length = text_width(s, scale);
  for (size_t i = 0; i < s.size(); ++i) {
    const auto g = glyph(s[i]);
    const int oy = y + length - static_cast<int>(i) * (kGlyphWidth + 1) * scale;  // first character at the bottom
    for (int row = 0; row < kGlyphHeight; ++row)
      for (int col = 0; col < kGlyphWidth; ++col)
        if (g[static_cast<size_t>(row)] & (1 << (kGlyphWidth - 1 - col)))
          fill_rect(x + row * scale, oy - (col + 1) * scale, x + (row + 1) * scale, oy - col * scale, c);
  }
}

}  // namespace cohort::app
