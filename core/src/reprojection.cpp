#include "cohort/core/reprojection.h"

#include <algorithm>
#include <stdexcept>

#include "cohort/core/host_threads.h"
#include "cohort/kernel/reproject.h"

namespace cohort::core {

namespace {

constexpr size_t kRowsPerTask = 8;

}  // namespace

void TemporalReprojection::reset() {
  image_ = FrameBuffer{};
  length_.clear();
  moments_.clear();
  depth_.clear();
  normal_.clear();
  id_.clear();
}

double TemporalReprojection::mean_history_length() const {
  if (length_.empty()) return 0.0;
  double sum = 0.0;
  for (float n : length_) sum += n;
  return sum / static_cast<double>(length_.size());
}

KReprojectParams reproject_params(const ReprojectionOptions& o, int width, int height, bool have_history) {
  KReprojectParams params{};
  params.width = width;
  params.height = height;
  params.have_history = have_history ? 1 : 0;
  params.moments = o.luminance_moments ? 1 : 0;
  params.max_history = static_cast<float>(std::max(o.max_history, 1));
  params.depth_tolerance = o.depth_tolerance;
  params.normal_cos = o.normal_cos;
  params.clamp_sigma = o.clamp_sigma;
  params.still_motion = o.still_motion;
  params.anti_lag_sigma = o.anti_lag_sigma;
  params.anti_lag_relative = o.anti_lag_relative;
  params.footprint_taps = o.jittered_planes ? 1 : 0;
  return params;
}

void TemporalReprojection::accumulate(const FrameBuffer& fresh, const GBuffer& gbuffer) {
  if (gbuffer.width != fresh.width || gbuffer.height != fresh.height)
    throw std::invalid_argument("TemporalReprojection: the G-buffer's size differs from the frame's");
  const int width = fresh.width, height = fresh.height;
  const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
  const bool have_history = image_.width == width && image_.height == height && length_.size() == pixels;
  if (next_image_.width != width || next_image_.height != height) next_image_.resize(width, height);
  next_length_.resize(pixels);
  next_depth_.resize(pixels);
  next_normal_.resize(3 * pixels);
  next_id_.resize(pixels);
  const bool moments = options_.luminance_moments;
  if (moments) {
    next_moments_.resize(2 * pixels);
    if (moments_.size() != 2 * pixels) moments_.assign(2 * pixels, 0.0f);
  }
  const KReprojectParams params = reproject_params(options_, width, height, have_history);

  ycocgw_.resize(4 * pixels);
  const KReprojectFresh fresh_planes{fresh.rgba.data(), ycocgw_.data(),     gbuffer.depth.data(), gbuffer.prev_depth.data(),
                                     gbuffer.motion.data(), gbuffer.normal.data(), gbuffer.id.data(),
                                     gbuffer.albedo.data()};
  const KReprojectHistory history{image_.rgba.data(), length_.data(), depth_.data(), normal_.data(), id_.data(),
                                  moments ? moments_.data() : nullptr};
  const KReprojectState next{next_image_.rgba.data(), next_length_.data(), next_depth_.data(), next_normal_.data(),
                             next_id_.data(), moments ? next_moments_.data() : nullptr};
  HostThreads::shared().for_ranges(pixels, 4096, [&](size_t begin, size_t end) {
    for (size_t p = begin; p < end; ++p) k_reproject_prepare(fresh.rgba.data(), ycocgw_.data(), static_cast<kint>(p));
  });
  HostThreads::shared().for_ranges(static_cast<size_t>(height), kRowsPerTask, [&](size_t row_begin, size_t row_end) {
    for (int y = static_cast<int>(row_begin); y < static_cast<int>(row_end); ++y)
      for (int x = 0; x < width; ++x) k_reproject_pixel(&params, &fresh_planes, &history, &next, x, y);
  });
  std::swap(image_, next_image_);
  std::swap(length_, next_length_);
  if (moments) std::swap(moments_, next_moments_);
  std::swap(depth_, next_depth_);
  std::swap(normal_, next_normal_);
  std::swap(id_, next_id_);
}

}  // namespace cohort::core
