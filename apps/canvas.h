// A small RGBA8 raster for charts: rectangles, thick lines, 5x7 text.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace cohort::app {

struct Rgb {
  uint8_t r, g, b;
};

class Canvas {
 public:
  Canvas(int width, int height, Rgb background);
  int width() const { return width_; }
  int height() const { return height_; }
  const std::vector<uint8_t>& rgba() const { return pixels_; }

  void fill_rect(int x0, int y0, int x1, int y1, Rgb c);
  void line(double x0, double y0, double x1, double y1, Rgb c, int thickness = 1);
  // Text with its top-left corner at (x, y), each font pixel drawn scale x scale.
  void text(int x, int y, const std::string& s, Rgb c, int scale = 2);
  // Text rotated 90 degrees counter-clockwise (reads bottom to top), top-left of its box at (x, y).
  void text_vertical(int x, int y, const std::string& s, Rgb c, int scale = 2);
  static int text_width(const std::string& s, int scale = 2);
  static int text_height(int scale = 2);

 private:
  void put(int x, int y, Rgb c);
  int width_, height_;
  std::vector<uint8_t> pixels_;
};

}  // namespace cohort::app
