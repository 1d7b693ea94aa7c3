#include "cohort/core/upsample.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "cohort/core/host_threads.h"
#include "cohort/kernel/upsample.h"

namespace cohort::core {

UpsampleMethod parse_upsample_method(const std::string& name) {
  if (name == "joint-bilateral") return UpsampleMethod::joint_bilateral;
  if (name == "nearest") return UpsampleMethod::nearest;
  if (name == "bilinear") return UpsampleMethod::bilinear;
  throw std::invalid_argument("unknown upsampling method '" + name + "' (expected joint-bilateral, nearest or bilinear)");
}

const char* upsample_method_name(UpsampleMethod method) {
  switch (method) {
    case UpsampleMethod::joint_bilateral: return "joint-bilateral";
    case UpsampleMethod::nearest: return "nearest";
    case UpsampleMethod::bilinear: return "bilinear";
  }
  return "?";
}

PathPattern path_pattern_for_scale(double scale, uint64_t frame) {
  PathPattern p;
  if (!(scale < 1.0)) return p;  // every pixel (NaN too)
  const double share = std::clamp(scale, 0.0, 1.0);
  p.pixels = static_cast<uint32_t>(std::clamp(std::lround(share * share * K_PATH_PATTERN_PIXELS), 1L, 16L));
  if (p.pixels >= K_PATH_PATTERN_PIXELS) return PathPattern{};
  p.phase = static_cast<uint32_t>((frame * p.pixels) % K_PATH_PATTERN_PIXELS);
  return p;
}

double path_pattern_scale(const PathPattern& pattern) {
  return pattern.sparse() ? std::sqrt(double(pattern.pixels) / K_PATH_PATTERN_PIXELS) : 1.0;
}

void upsample_sparse(const FrameBuffer& sparse, const GBuffer& gbuffer, PathPattern pattern, UpsampleMethod method,
                     FrameBuffer& out) {
  SparseUpsampler().upsample(sparse, gbuffer, pattern, method, out);
}

void SparseUpsampler::upsample(const FrameBuffer& sparse, const GBuffer& gbuffer, PathPattern pattern,
                               UpsampleMethod method, FrameBuffer& out) {
  if (method == UpsampleMethod::bilinear)
    throw std::invalid_argument("upsample_sparse: bilinear stretches a small frame (stretch_bilinear)");
  if (gbuffer.width != sparse.width || gbuffer.height != sparse.height)
    throw std::invalid_argument("upsample_sparse: the G-buffer (" + std::to_string(gbuffer.width) + "x" +
                                std::to_string(gbuffer.height) + ") is not the frame's size (" +
                                std::to_string(sparse.width) + "x" + std::to_string(sparse.height) + ")");
  if (out.width != sparse.width || out.height != sparse.height) out.resize(sparse.width, sparse.height);
  const KUpsampleParams params = k_upsample_params(sparse.width, sparse.height, pattern.pixels, pattern.phase);
  const int kernel_method = method == UpsampleMethod::nearest ? K_UPSAMPLE_NEAREST : K_UPSAMPLE_JOINT_BILATERAL;
  HostThreads& threads = HostThreads::shared();
  const float* illumination = sparse.rgba.data();  // nearest reads the colour only
  if (method == UpsampleMethod::joint_bilateral) {
    illumination_.resize(sparse.rgba.size());
    threads.for_ranges(static_cast<size_t>(sparse.height), 16, [&](size_t row_begin, size_t row_end) {
      for (size_t y = row_begin; y < row_end; ++y)
        for (int x = 0; x < sparse.width; ++x)
          k_upsample_demodulate_pixel(sparse.rgba.data(), gbuffer.albedo.data(), illumination_.data(), &params, x,
                                      static_cast<kint>(y));
    });
    illumination = illumination_.data();
  }
  threads.for_ranges(static_cast<size_t>(sparse.height), 4, [&](size_t row_begin, size_t row_end) {
    for (size_t y = row_begin; y < row_end; ++y)
      for (int x = 0; x < sparse.width; ++x)
        k_upsample_pixel(sparse.rgba.data(), illumination, gbuffer.depth.data(), gbuffer.normal.data(),
                         gbuffer.albedo.data(), gbuffer.id.data(), out.rgba.data(), &params, kernel_method, x,
                         static_cast<kint>(y));
  });
}

void stretch_bilinear(const FrameBuffer& low, int width, int height, FrameBuffer& out) {
  if (low.width <= 0 || low.height <= 0) throw std::invalid_argument("stretch_bilinear: an empty frame");
  if (out.width != width || out.height != height) out.resize(width, height);
  const float sx = float(low.width) / float(width), sy = float(low.height) / float(height);
  HostThreads::shared().for_ranges(static_cast<size_t>(height), 8, [&](size_t row_begin, size_t row_end) {
    for (size_t y = row_begin; y < row_end; ++y) {
      const float fy = std::clamp((float(y) + 0.5f) * sy - 0.5f, 0.0f, float(low.height - 1));
      const int y0 = int(fy), y1 = std::min(y0 + 1, low.height - 1);
      const float ty = fy - float(y0);
      float* dst = out.row(int(y));
      for (int x = 0; x < width; ++x) {
        const float fx = std::clamp((float(x) + 0.5f) * sx - 0.5f, 0.0f, float(low.width - 1));
        const int x0 = int(fx), x1 = std::min(x0 + 1, low.width - 1);
        const float tx = fx - float(x0);
        const float* a = low.row(y0) + 4 * x0;
        const float* b = low.row(y0) + 4 * x1;
        const float* c = low.row(y1) + 4 * x0;
        const float* d = low.row(y1) + 4 * x1;
        for (int k = 0; k < 4; ++k)
          dst[4 * x + k] = (a[k] * (1.0f - tx) + b[k] * tx) * (1.0f - ty) + (c[k] * (1.0f - tx) + d[k] * tx) * ty;
      }
    }
  });
}

}  // namespace cohort::core
