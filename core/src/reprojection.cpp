#include "cohort/core/reprojection.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "cohort/core/host_threads.h"

namespace cohort::core {

namespace {

constexpr size_t kRowsPerTask = 8;

struct YCoCg {
  float y, co, cg;
};
inline YCoCg to_ycocg(const float* c) {
  return {0.25f * c[0] + 0.5f * c[1] + 0.25f * c[2], 0.5f * c[0] - 0.5f * c[2], -0.25f * c[0] + 0.5f * c[1] - 0.25f * c[2]};
}
inline void from_ycocg(YCoCg v, float* c) {
  const float t = v.y - v.cg;
  c[0] = t + v.co;
  c[1] = v.y + v.cg;
  c[2] = t - v.co;
}
inline bool finite_rgb(const float* c) { return std::isfinite(c[0]) && std::isfinite(c[1]) && std::isfinite(c[2]); }

}  // namespace

void TemporalReprojection::reset() {
  image_ = FrameBuffer{};
  length_.clear();
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
  const ReprojectionOptions& o = options_;
  const float max_history = static_cast<float>(std::max(o.max_history, 1));

  // The fresh frame in YCoCg once, for the neighbourhood moments (non-finite samples flagged).
  ycocg_.resize(3 * pixels);
  finite_.resize(pixels);
  HostThreads::shared().for_ranges(pixels, 4096, [&](size_t begin, size_t end) {
    for (size_t p = begin; p < end; ++p) {
      const float* c = fresh.rgba.data() + 4 * p;
      const bool ok = finite_rgb(c);
      const YCoCg v = ok ? to_ycocg(c) : YCoCg{0.0f, 0.0f, 0.0f};
      ycocg_[3 * p] = v.y, ycocg_[3 * p + 1] = v.co, ycocg_[3 * p + 2] = v.cg;
      finite_[p] = ok ? 1 : 0;
    }
  });
  HostThreads::shared().for_ranges(static_cast<size_t>(height), kRowsPerTask, [&](size_t row_begin, size_t row_end) {
    for (int y = static_cast<int>(row_begin); y < static_cast<int>(row_end); ++y) {
      for (int x = 0; x < width; ++x) {
        const size_t p = static_cast<size_t>(y) * width + x;
        const float* sample = fresh.rgba.data() + 4 * p;
        // This frame's surfaces become the next frame's history tests (copied here, in parallel, while
        // they are in cache, rather than in a serial pass at the end).
        next_depth_[p] = gbuffer.depth[p];
        next_id_[p] = gbuffer.id[p];
        for (int k = 0; k < 3; ++k) next_normal_[3 * p + k] = gbuffer.normal[3 * p + k];
        // Neighbourhood moments of the fresh frame in YCoCg (finite samples only), when needed.
        float m1[3] = {0, 0, 0}, m2[3] = {0, 0, 0};
        int count = 0;
        auto moments = [&] {
          for (int dy = -1; dy <= 1; ++dy) {
            const int ny = y + dy;
            if (ny < 0 || ny >= height) continue;
            for (int dx = -1; dx <= 1; ++dx) {
              const int nx = x + dx;
              if (nx < 0 || nx >= width) continue;
              const size_t q = static_cast<size_t>(ny) * width + nx;
              if (!finite_[q]) continue;
              const float* v = ycocg_.data() + 3 * q;
              for (int k = 0; k < 3; ++k) {
                m1[k] += v[k];
                m2[k] += v[k] * v[k];
              }
              ++count;
            }
          }
        };
        // The history, reprojected: bilinear over the taps that saw the same surface.
        float history[3] = {0, 0, 0};
        float history_length = 0.0f;
        const float mx = gbuffer.motion[2 * p], my = gbuffer.motion[2 * p + 1];
        const bool moved = std::fabs(mx) > o.still_motion || std::fabs(my) > o.still_motion;
        if (have_history && std::fabs(mx) < 1e8f) {
          const float hx = static_cast<float>(x) + mx, hy = static_cast<float>(y) + my;  // pixel-centre space
          const float fx = std::floor(hx), fy = std::floor(hy);
          const float wx = hx - fx, wy = hy - fy;
          const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
          const uint32_t id = gbuffer.id[p];
          const float expected_depth = gbuffer.prev_depth[p];
          const float* n = gbuffer.normal.data() + 3 * p;
          float weight_sum = 0.0f, length_sum = 0.0f;
          for (int t = 0; t < 4; ++t) {
            const int tx = x0 + (t & 1), ty = y0 + (t >> 1);
            const float w = ((t & 1) ? wx : 1.0f - wx) * ((t >> 1) ? wy : 1.0f - wy);
            if (w <= 0.0f || tx < 0 || ty < 0 || tx >= width || ty >= height) continue;
            const size_t q = static_cast<size_t>(ty) * width + tx;
            if (id_[q] != id || !(length_[q] > 0.0f)) continue;
            if (id != 0xFFFFFFFFu) {  // a surface: same depth and orientation as the history's
              if (std::fabs(depth_[q] - expected_depth) > o.depth_tolerance * std::max(expected_depth, 1e-3f)) continue;
              const float* hn = normal_.data() + 3 * q;
              if (n[0] * hn[0] + n[1] * hn[1] + n[2] * hn[2] < o.normal_cos) continue;
            }
            const float* h = image_.rgba.data() + 4 * q;
            history[0] += w * h[0], history[1] += w * h[1], history[2] += w * h[2];
            length_sum += w * length_[q];
            weight_sum += w;
          }
          if (weight_sum > 1e-3f) {
            const float inv = 1.0f / weight_sum;
            history[0] *= inv, history[1] *= inv, history[2] *= inv;
            history_length = length_sum * inv;
          }
        }
        if (history_length > 0.0f && moved) moments();
        if (history_length > 0.0f && moved && count > 0) {
          const float inv = 1.0f / static_cast<float>(count);
          YCoCg h = to_ycocg(history);
          float* hv[3] = {&h.y, &h.co, &h.cg};
          for (int k = 0; k < 3; ++k) {
            const float mean = m1[k] * inv;
            const float sigma = std::sqrt(std::max(m2[k] * inv - mean * mean, 0.0f));
            *hv[k] = std::clamp(*hv[k], mean - o.clamp_sigma * sigma, mean + o.clamp_sigma * sigma);
          }
          from_ycocg(h, history);
        }
        float* out = next_image_.rgba.data() + 4 * p;
        out[3] = 1.0f;
        if (finite_rgb(sample)) {
          const float n = std::min(history_length + 1.0f, max_history);
          const float f = history_length > 0.0f ? 1.0f / n : 1.0f;
          for (int k = 0; k < 3; ++k) out[k] = history[k] + f * (sample[k] - history[k]);
          next_length_[p] = history_length > 0.0f ? n : 1.0f;
        } else if (history_length > 0.0f) {
          for (int k = 0; k < 3; ++k) out[k] = history[k];
          next_length_[p] = history_length;
        } else {
          // No usable sample and no history: show the neighbourhood's mean, keep no history.
          moments();
          const float inv = count > 0 ? 1.0f / static_cast<float>(count) : 0.0f;
          YCoCg mean{m1[0] * inv, m1[1] * inv, m1[2] * inv};
          from_ycocg(mean, out);
          next_length_[p] = 0.0f;
        }
      }
    }
  });
  std::swap(image_, next_image_);
  std::swap(length_, next_length_);
  std::swap(depth_, next_depth_);
  std::swap(normal_, next_normal_);
  std::swap(id_, next_id_);
}

}  // namespace cohort::core
