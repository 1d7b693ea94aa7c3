#include "cohort/core/atrous_filter.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "cohort/core/host_threads.h"
#include "cohort/kernel/atrous.h"
#include "cohort/kernel/firefly.h"
#include "cohort/kernel/svgf.h"

namespace cohort::core {

namespace {

constexpr size_t kRowsPerTask = 8;
}  // namespace

int atrous_normal_squarings(int power) {
  int squarings = 0;
  while ((1 << squarings) < power && squarings < 30) ++squarings;
  if (power < 1 || (1 << squarings) != power)
    throw std::invalid_argument("AtrousFilter: the normal stop's power must be a power of two (1, 2, 4, ... 64), got " +
                                std::to_string(power));
  return squarings;
}


AtrousGuide parse_atrous_guide(const std::string& name) {
  if (name == "variance") return AtrousGuide::variance;
  if (name == "variance-of-mean") return AtrousGuide::variance_of_mean;
  if (name == "fixed") return AtrousGuide::fixed;
  throw std::invalid_argument("a-trous guide: expected variance, variance-of-mean or fixed, got '" + name + "'");
}

const char* atrous_guide_name(AtrousGuide guide) {
  return guide == AtrousGuide::variance ? "variance" : guide == AtrousGuide::variance_of_mean ? "variance-of-mean" : "fixed";
}

bool atrous_guide_uses_variance(AtrousGuide guide) { return guide != AtrousGuide::fixed; }

KHistoryFixParams history_fix_params(const AtrousOptions& options, int width, int height, bool guided) {
  KHistoryFixParams p{};
  p.width = width;
  p.height = height;
  p.normal_squarings = atrous_normal_squarings(options.normal_power);
  p.guided = guided ? 1 : 0;
  p.frames = options.history_fix_frames;
  p.stride = options.history_fix_stride > 0.0f ? std::max(options.history_fix_stride, 1.0f)
                                               : static_cast<float>(history_fix_stride_for_height(height));
  p.depth_sigma = options.depth_sigma;
  p.min_length = options.history_fix_min_length;
  p.color_sigma = (guided ? options.variance_sigma : options.color_sigma) * options.history_fix_sigma_scale;
  return p;
}

int history_fix_stride_for_height(int height) { return std::max(1, (height + 90) / 180); }

int atrous_passes_for_height(int height) {
  if (height <= 360) return 1;
  if (height <= 540) return 2;
  int passes = 3;
  for (int rows = 1440; rows < height && passes < 5; rows *= 2) ++passes;
  return passes;
}

void AtrousFilter::apply(const FrameBuffer& frame, const GBuffer& gbuffer, FrameBuffer& out,
                         const AtrousHistory& history) {
  if (gbuffer.width != frame.width || gbuffer.height != frame.height)
    throw std::invalid_argument("AtrousFilter: the G-buffer's size differs from the frame's");
  const int width = frame.width, height = frame.height;
  const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
  for (FrameBuffer* b : {&ping_, &pong_, &out})
    if (b->width != width || b->height != height) b->resize(width, height);
  HostThreads& threads = HostThreads::shared();
  threads.for_ranges(pixels, 16384, [&](size_t begin, size_t end) {
    for (size_t p = begin; p < end; ++p)
      k_atrous_modulate(frame.rgba.data(), gbuffer.albedo.data(), ping_.rgba.data(), static_cast<kint>(p), 0);
  });
  if (options_.firefly_factor > 0.0f) {
    const float factor = options_.firefly_factor;
    threads.for_ranges(static_cast<size_t>(height), kRowsPerTask, [&](size_t row_begin, size_t row_end) {
      for (int y = static_cast<int>(row_begin); y < static_cast<int>(row_end); ++y)
        for (int x = 0; x < width; ++x)
          k_firefly_clamp_pixel(ping_.rgba.data(), pong_.rgba.data(), width, height, factor, x, y);
    });
    std::swap(ping_, pong_);
  }
  const bool variance = atrous_guide_uses_variance(options_.guide);
  KAtrousParams params{};
  params.width = width;
  params.height = height;
  params.normal_squarings = atrous_normal_squarings(options_.normal_power);
  params.depth_sigma = options_.depth_sigma;
  params.color_sigma = variance ? options_.variance_sigma : options_.color_sigma;
  const auto rows = [&](auto&& pixel) {
    threads.for_ranges(static_cast<size_t>(height), kRowsPerTask, [&](size_t row_begin, size_t row_end) {
      for (int y = static_cast<int>(row_begin); y < static_cast<int>(row_end); ++y)
        for (int x = 0; x < width; ++x) pixel(x, y);
    });
  };
  geometry_.resize(4 * pixels);
  threads.for_ranges(pixels, 16384, [&](size_t begin, size_t end) {
    for (size_t p = begin; p < end; ++p)
      k_atrous_pack_geometry(gbuffer.depth.data(), gbuffer.normal.data(), geometry_.data(), static_cast<kint>(p));
  });
  if (variance) {
    estimated_variance_.resize(pixels);
    KSvgfVarianceParams v{};
    v.width = width;
    v.height = height;
    v.normal_squarings = params.normal_squarings;
    v.have_history = history.moments && history.length ? 1 : 0;
    v.depth_sigma = options_.depth_sigma;
    v.short_history = options_.short_history;
    v.of_mean = options_.guide == AtrousGuide::variance_of_mean ? 1 : 0;
    // The passes carry the variance in the illumination's alpha; each pixel writes its own alpha and
    // reads only its neighbours' RGB.
    rows([&](int x, int y) {
      const size_t p = static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x);
      estimated_variance_[p] = k_svgf_variance_estimate(ping_.rgba.data(), history.moments, history.length,
                                                        geometry_.data(), &v, x, y);
      ping_.rgba[4 * p + 3] = estimated_variance_[p];
    });
  }
  FrameBuffer* from = &ping_;
  FrameBuffer* to = &pong_;
  if (options_.history_fix_frames > 0.0f && history.length) {
    const KHistoryFixParams fix = history_fix_params(options_, width, height, variance);
    rows([&](int x, int y) {
      k_svgf_history_fix_pixel(from->rgba.data(), to->rgba.data(), geometry_.data(), gbuffer.id.data(), history.length,
                               &fix, x, y);
    });
    std::swap(from, to);
  }
  for (int pass = 0; pass < std::max(options_.passes, 0); ++pass) {
    params.step = 1 << pass;
    if (variance)
      rows([&](int x, int y) { k_svgf_atrous_pixel(from->rgba.data(), to->rgba.data(), geometry_.data(), &params, x, y); });
    else
      rows([&](int x, int y) { k_atrous_pixel(from->rgba.data(), to->rgba.data(), geometry_.data(), &params, x, y); });
    std::swap(from, to);
  }
  threads.for_ranges(pixels, 16384, [&](size_t begin, size_t end) {
    for (size_t p = begin; p < end; ++p)
      k_atrous_modulate(from->rgba.data(), gbuffer.albedo.data(), out.rgba.data(), static_cast<kint>(p), 1);
  });
}

}  // namespace cohort::core
