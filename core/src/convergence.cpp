#include "cohort/core/convergence.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "cohort/core/host_threads.h"

namespace cohort::core {

namespace {

double angle_between_degrees(const float a[3], const float b[3]) {
  const double la = std::sqrt(double(a[0]) * a[0] + double(a[1]) * a[1] + double(a[2]) * a[2]);
  const double lb = std::sqrt(double(b[0]) * b[0] + double(b[1]) * b[1] + double(b[2]) * b[2]);
  if (la <= 0.0 || lb <= 0.0) return 0.0;
  const double c = (double(a[0]) * b[0] + double(a[1]) * b[1] + double(a[2]) * b[2]) / (la * lb);
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

}  // namespace

void AdaptiveConvergence::reset() {
  have_previous_ = false;
  effective_frames_ = 0.0;
}

double AdaptiveConvergence::next_factor(const KCamera& camera) {
  double f = 1.0;
  if (have_previous_ && camera.width == previous_.width && camera.height == previous_.height) {
    const double dx = camera.origin[0] - previous_.origin[0], dy = camera.origin[1] - previous_.origin[1],
                 dz = camera.origin[2] - previous_.origin[2];
    const double translation = std::sqrt(dx * dx + dy * dy + dz * dz);
    // Rotation: the larger of the view direction's turn and the roll of the up vector.
    const double rotation = std::max(angle_between_degrees(camera.forward, previous_.forward),
                                     angle_between_degrees(camera.up, previous_.up));
    const bool cut = translation >= options_.cut_translation || rotation >= options_.cut_rotation_degrees;
    const double motion = translation / options_.full_translation + rotation / options_.full_rotation_degrees;
    if (cut) {
      f = 1.0;
    } else if (motion <= 1e-6) {
      const double cap = std::max(1, options_.max_frames);
      f = 1.0 / std::min(effective_frames_ + 1.0, cap);
    } else {
      // Continue from what the image is worth now, but never keep more than motion allows.
      const double still = 1.0 / (effective_frames_ + 1.0);
      f = std::clamp(std::max(still, options_.moving_floor + (1.0 - options_.moving_floor) * motion), options_.moving_floor, 1.0);
    }
  }
  previous_ = camera;
  have_previous_ = true;
  effective_frames_ = 1.0 / f;
  return f;
}

namespace {

// Throws std::invalid_argument unless the frame's plane and the mask fit its size; returns its pixels.
size_t checked_pixels(const FrameBuffer& fresh, const std::vector<float>* motion_mask) {
  const size_t pixels = static_cast<size_t>(fresh.width) * fresh.height;
  if (fresh.rgba.size() != pixels * 4) throw std::invalid_argument("AdaptiveConvergence: frame buffer size mismatch");
  if (motion_mask && motion_mask->size() != pixels)
    throw std::invalid_argument("AdaptiveConvergence: motion mask has " + std::to_string(motion_mask->size()) +
                                " values for " + std::to_string(pixels) + " pixels");
  return pixels;
}

}  // namespace

double AdaptiveConvergence::accumulate(const KCamera& camera, const FrameBuffer& fresh, const std::vector<float>* motion_mask) {
  checked_pixels(fresh, motion_mask);
  if (fresh.width != accumulated_.width || fresh.height != accumulated_.height) reset();
  const double f = next_factor(camera);
  blend(fresh, f, motion_mask);
  return f;
}

void AdaptiveConvergence::blend(const FrameBuffer& fresh, double f, const std::vector<float>* motion_mask) {
  const size_t pixels = checked_pixels(fresh, motion_mask);
  if (f >= 1.0 || fresh.width != accumulated_.width || fresh.height != accumulated_.height) {
    accumulated_ = fresh;
    return;
  }
  const float global = static_cast<float>(f);
  const float object_f = static_cast<float>(options_.moving_object_f);
  constexpr size_t kPixelsPerRange = 16384;  // smaller ranges cost more to hand out than they save
  // Restrict pointers and the mask test outside the loops, so that both loops vectorise.
  float* __restrict accumulated = accumulated_.rgba.data();
  const float* __restrict incoming = fresh.rgba.data();
  const float* __restrict mask = motion_mask ? motion_mask->data() : nullptr;
  HostThreads::shared().for_ranges(pixels, kPixelsPerRange, [=](size_t begin, size_t end) {
    if (!mask) {
      for (size_t i = 4 * begin; i < 4 * end; ++i) accumulated[i] = converge(accumulated[i], incoming[i], global);
      return;
    }
    for (size_t p = begin; p < end; ++p) {
      const float fp = std::max(global, std::clamp(mask[p], 0.0f, 1.0f) * object_f);
      for (size_t k = 4 * p; k < 4 * p + 4; ++k) accumulated[k] = converge(accumulated[k], incoming[k], fp);
    }
  });
}

}  // namespace cohort::core
