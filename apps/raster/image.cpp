#include "image.h"

#include <cmath>

#include "font.h"

namespace cohort::raster {
namespace {

void blend_pixel(Image8& image, int x, int y, Rgba8 color) {
  if (x < 0 || y < 0 || x >= image.width || y >= image.height) return;
  uint8_t* p = &image.rgba[(static_cast<size_t>(y) * image.width + x) * 4];
  if (color.a == 255) {
    p[0] = color.r; p[1] = color.g; p[2] = color.b; p[3] = 255;
    return;
  }
  // "over" compositing onto whatever is there (the HUD layer starts transparent).
  const int a = color.a, inv = 255 - a;
  p[0] = static_cast<uint8_t>((color.r * a + p[0] * inv) / 255);
  p[1] = static_cast<uint8_t>((color.g * a + p[1] * inv) / 255);
  p[2] = static_cast<uint8_t>((color.b * a + p[2] * inv) / 255);
  p[3] = static_cast<uint8_t>(a + p[3] * inv / 255);
}

}  // namespace

void fill_rect(Image8& image, int x, int y, int w, int h, Rgba8 color) {
  const int x0 = std::max(x, 0), y0 = std::max(y, 0);
  const int x1 = std::min(x + w, image.width), y1 = std::min(y + h, image.height);
  for (int py = y0; py < y1; ++py)
    for (int px = x0; px < x1; ++px) blend_pixel(image, px, py, color);
}

void draw_line(Image8& image, double x0, double y0, double x1, double y1, Rgba8 color, int thickness) {
  // Two dots per pixel of the longer axis, so steep and shallow lines both come out without gaps.
  const double length = std::max(std::abs(x1 - x0), std::abs(y1 - y0));
  const int steps = std::max(1, static_cast<int>(std::ceil(length * 2.0)));
  const int lo = -(thickness - 1) / 2, hi = thickness / 2;
  for (int i = 0; i <= steps; ++i) {
    const double t = static_cast<double>(i) / steps;
    const int x = static_cast<int>(std::lround(x0 + (x1 - x0) * t)), y = static_cast<int>(std::lround(y0 + (y1 - y0) * t));
    for (int dy = lo; dy <= hi; ++dy)
      for (int dx = lo; dx <= hi; ++dx) blend_pixel(image, x + dx, y + dy, color);
  }
}

int draw_text(Image8& image, int x, int y, std::string_view text, Rgba8 color, int scale) {
  scale = std::max(scale, 1);
  for (char c : text) {
    for (int gy = 0; gy < kGlyphHeight; ++gy)
      for (int gx = 0; gx < kGlyphWidth; ++gx)
        if (glyph_pixel(c, gx, gy)) fill_rect(image, x + gx * scale, y + gy * scale, scale, scale, color);
    x += kGlyphAdvance * scale;
  }
  return x;
}

void draw_text_vertical(Image8& image, int x, int y, std::string_view text, Rgba8 color, int scale) {
  scale = std::max(scale, 1);
  int baseline = y + text_advance(text, scale);  // the first character sits at the bottom
  for (char c : text) {
    // Glyph row gy becomes column x + gy; glyph column gx rises from the baseline.
    for (int gy = 0; gy < kGlyphHeight; ++gy)
      for (int gx = 0; gx < kGlyphWidth; ++gx)
        if (glyph_pixel(c, gx, gy)) fill_rect(image, x + gy * scale, baseline - (gx + 1) * scale, scale, scale, color);
    baseline -= kGlyphAdvance * scale;
  }
}

int text_width(std::string_view text, int scale) {
  return text.empty() ? 0 : text_advance(text, scale) - scale;
}

int text_advance(std::string_view text, int scale) { return static_cast<int>(text.size()) * kGlyphAdvance * scale; }

int text_height(int scale) { return kGlyphHeight * scale; }

}  // namespace cohort::raster
