// An RGBA8 image and what the viewer's HUD and the benchmark charts draw on it: rectangles, thick
// lines and text in the 5x7 font (raster/font.h). Everything is clipped to the image.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string_view>
#include <vector>

namespace cohort::raster {

struct Rgba8 {
  uint8_t r = 255, g = 255, b = 255, a = 255;
};

// Rows top to bottom.
struct Image8 {
  int width = 0, height = 0;
  std::vector<uint8_t> rgba;
  void resize(int w, int h) { width = w; height = h; rgba.assign(static_cast<size_t>(w) * h * 4, 0); }
  void clear() { std::fill(rgba.begin(), rgba.end(), uint8_t{0}); }
};

// Opaque colours replace what is there; translucent ones (a < 255) are composited over it, e.g. the
// box behind the HUD text on its transparent layer.
void fill_rect(Image8& image, int x, int y, int w, int h, Rgba8 color);
// Square dots `thickness` pixels wide along the line, both ends included.
void draw_line(Image8& image, double x0, double y0, double x1, double y1, Rgba8 color, int thickness = 1);

// Text with its top-left corner at (x, y), each font pixel scale x scale. Returns the x just past the
// last glyph's spacing column: x + text_advance(text, scale).
int draw_text(Image8& image, int x, int y, std::string_view text, Rgba8 color, int scale = 1);
// Text turned 90 degrees counter-clockwise (reads bottom to top), in the text_height(scale) wide and
// text_advance(text, scale) tall box whose top-left corner is (x, y).
void draw_text_vertical(Image8& image, int x, int y, std::string_view text, Rgba8 color, int scale = 1);
// Width of the ink: the last glyph's spacing column left out.
int text_width(std::string_view text, int scale = 1);
// How far draw_text moves: every glyph with its spacing column.
int text_advance(std::string_view text, int scale = 1);
int text_height(int scale = 1);

}  // namespace cohort::raster
