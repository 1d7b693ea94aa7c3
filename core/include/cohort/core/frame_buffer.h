#pragma once

#include <cstddef>
#include <vector>

namespace cohort::core {

// Linear HDR RGBA, rows top to bottom.
struct FrameBuffer {
  int width = 0, height = 0;
  std::vector<float> rgba;
  void resize(int w, int h) { width = w; height = h; rgba.assign(static_cast<size_t>(w) * h * 4, 0.0f); }
  float* row(int y) { return rgba.data() + static_cast<size_t>(y) * width * 4; }
  const float* row(int y) const { return rgba.data() + static_cast<size_t>(y) * width * 4; }
};

}  // namespace cohort::core
