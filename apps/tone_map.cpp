#include "tone_map.h"

#include <algorithm>
#include <cmath>

namespace cohort::app {

namespace {

float aces(float x) {
  const float a = 2.51f, b = 0.03f, c = 2.43f, d = 0.59f, e = 0.14f;
  return std::clamp((x * (a * x + b)) / (x * (c * x + d) + e), 0.0f, 1.0f);
}

}  // namespace

std::vector<uint8_t> tone_map(const core::FrameBuffer& frame, const ToneMapOptions& options) {
  std::vector<uint8_t> out(frame.rgba.size());
  const float inv_gamma = 1.0f / options.gamma;
  for (size_t i = 0; i < frame.rgba.size(); ++i) {
    float v = frame.rgba[i];
    if (!std::isfinite(v)) v = 0.0f;
    v = (i % 4 == 3) ? std::clamp(v, 0.0f, 1.0f) : std::pow(aces(std::max(v, 0.0f) * options.exposure), inv_gamma);
    out[i] = static_cast<uint8_t>(v * 255.0f + 0.5f);
  }
  return out;
}

}  // namespace cohort::app
