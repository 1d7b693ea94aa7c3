// A 5x7 bitmap font for the HUD, rasterised straight onto an RGBA8 image (no GL text, no font files).
// Covers printable ASCII from ' ' to '_' plus '|'; lowercase letters are drawn as capitals, anything
// else as '?'.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string_view>
#include <vector>

namespace cohort::viewer {

constexpr int kGlyphWidth = 5;
constexpr int kGlyphHeight = 7;
constexpr int kGlyphAdvance = 6;     // one column of spacing
constexpr int kLineAdvance = 9;      // two rows of spacing

// Whether pixel (x, y) of the glyph for c is set; x in [0,5), y in [0,7) top to bottom.
bool glyph_pixel(char c, int x, int y);

struct Rgba8 {
  uint8_t r = 255, g = 255, b = 255, a = 255;
};

// An RGBA8 image, rows top to bottom.
struct Image8 {
  int width = 0, height = 0;
  std::vector<uint8_t> rgba;
  void resize(int w, int h) { width = w; height = h; rgba.assign(static_cast<size_t>(w) * h * 4, 0); }
  void clear() { std::fill(rgba.begin(), rgba.end(), uint8_t{0}); }
};

// Draw text with its top-left corner at (x, y), each font pixel scale x scale; clipped to the image.
// Returns the x just past the last glyph.
int draw_text(Image8& image, int x, int y, std::string_view text, Rgba8 color, int scale = 1);
// Fill a rectangle (clipped), e.g. a translucent box behind HUD text.
void fill_rect(Image8& image, int x, int y, int w, int h, Rgba8 color);
int text_width(std::string_view text, int scale = 1);

}  // namespace cohort::viewer
