// The history fix (kernel/svgf.h's k_svgf_history_fix_pixel, run by core/atrous_filter.h before the passes):
// pixels with a short reprojected history get a wide edge-aware blur, pixels with a long one are left
// exactly as they were, the blur stops at depth, normal and entity edges, and NaN or Inf never spreads.
// The passes are off (passes = 0) so that what changes is the fix alone.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "cohort/core/atrous_filter.h"
#include "cohort/kernel/svgf.h"
#include "still_wall.h"

using namespace cohort::core;

namespace {

constexpr int kW = 48, kH = 32;

GBuffer wall() { return cohort::test::still_wall(kW, kH, 0.5f); }

// Light level `light(x, y)` times (1 + uniform noise of +-noise), times the albedo.
template <typename Light>
FrameBuffer lit(const GBuffer& g, float noise, Light light, unsigned seed = 7) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-noise, noise);
  FrameBuffer f;
  f.resize(kW, kH);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const size_t p = size_t(y) * kW + x;
      const float l = light(x, y) * (1.0f + u(rng));
      for (int k = 0; k < 3; ++k) f.rgba[4 * p + k] = l * g.albedo[3 * p + k];
      f.rgba[4 * p + 3] = 1.0f;
    }
  return f;
}

AtrousOptions fix_only(float frames) {
  AtrousOptions o;
  o.passes = 0;
  o.guide = AtrousGuide::fixed;
  o.history_fix_frames = frames;
  o.history_fix_stride = 3.0f;
  return o;
}

FrameBuffer filtered(const FrameBuffer& frame, const GBuffer& g, const std::vector<float>& length, float frames) {
  AtrousFilter filter(fix_only(frames));
  FrameBuffer out;
  filter.apply(frame, g, out, AtrousHistory{nullptr, length.data()});
  return out;
}

// Mean squared difference of the red channel from `expected` over the pixels in [x0, x1) x [y0, y1).
double mean_square_error(const FrameBuffer& f, float expected, int x0, int x1, int y0, int y1) {
  double sum = 0.0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const double d = f.rgba[4 * (size_t(y) * kW + x)] - expected;
      sum += d * d;
    }
  return sum / double((x1 - x0) * (y1 - y0));
}

}  // namespace

// Left half: a one-frame history; right half: 32 frames. The left half's noise drops several-fold; the right
// half comes out exactly as with the fix off.
TEST(HistoryFix, ShortHistoriesGetSmootherLongOnesAreUntouched) {
  const GBuffer g = wall();
  const FrameBuffer frame = lit(g, 0.5f, [](int, int) { return 1.0f; });
  std::vector<float> length(g.pixels());
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) length[size_t(y) * kW + x] = x < kW / 2 ? 1.0f : 32.0f;
  const FrameBuffer fixed = filtered(frame, g, length, 8.0f);
  const FrameBuffer off = filtered(frame, g, length, 0.0f);
  // Away from the halves' border (the short side's taps reach 6 pixels into the long side, which is fine).
  const double before = mean_square_error(off, 0.5f, 2, kW / 2 - 8, 2, kH - 2);
  const double after = mean_square_error(fixed, 0.5f, 2, kW / 2 - 8, 2, kH - 2);
  EXPECT_GT(before, 0.0);
  EXPECT_LT(after, before / 8.0) << "before " << before << " after " << after;
  for (int y = 0; y < kH; ++y)
    for (int x = kW / 2; x < kW; ++x)
      for (int k = 0; k < 4; ++k) {
        const size_t i = 4 * (size_t(y) * kW + x) + k;
        ASSERT_EQ(fixed.rgba[i], off.rgba[i]) << x << "," << y;
      }
}

// The longer the history, the narrower the blur: at 1 frame the taps lie `stride` apart, just short of
// `frames` one pixel apart, and from `frames` on (or with no history at all) the pixel is left alone.
TEST(HistoryFix, StrideShrinksAsTheHistoryGrows) {
  KHistoryFixParams p{};
  p.frames = 8.0f;
  p.stride = 4.0f;
  EXPECT_EQ(k_svgf_history_fix_stride(&p, 1.0f), 4);
  EXPECT_EQ(k_svgf_history_fix_stride(&p, 0.5f), 4);  // the anti-lag shortens lengths below one frame
  EXPECT_EQ(k_svgf_history_fix_stride(&p, 4.5f), 3);  // halfway: 2.5 rounds up
  EXPECT_EQ(k_svgf_history_fix_stride(&p, 5.5f), 2);
  EXPECT_EQ(k_svgf_history_fix_stride(&p, 7.9f), 1);
  EXPECT_EQ(k_svgf_history_fix_stride(&p, 8.0f), 0);
  EXPECT_EQ(k_svgf_history_fix_stride(&p, 0.0f), 0);
  EXPECT_EQ(k_svgf_history_fix_stride(&p, std::numeric_limits<float>::quiet_NaN()), 0);
  // Between, a pixel's stride never grows with its history.
  int previous = 4;
  for (float length = 1.0f; length < 8.0f; length += 0.25f) {
    const int stride = k_svgf_history_fix_stride(&p, length);
    EXPECT_LE(stride, previous);
    EXPECT_GE(stride, 1);
    previous = stride;
  }
}

// With a least length, fresh samples (1 frame: disoccluded, or the anti-lag dropped the history) are left to
// the passes exactly as they were, while the short histories above it are still smoothed.
TEST(HistoryFix, FreshSamplesBelowTheLeastLengthAreLeftAlone) {
  KHistoryFixParams p{};
  p.frames = 6.0f;
  p.stride = 2.0f;
  p.min_length = 1.5f;
  EXPECT_EQ(k_svgf_history_fix_stride(&p, 1.0f), 0);
  EXPECT_EQ(k_svgf_history_fix_stride(&p, 1.4f), 0);
  EXPECT_EQ(k_svgf_history_fix_stride(&p, 1.5f), 2);
  EXPECT_EQ(k_svgf_history_fix_stride(&p, 5.0f), 1);
  p.min_length = 0.0f;
  EXPECT_EQ(k_svgf_history_fix_stride(&p, 1.0f), 2);

  const GBuffer g = wall();
  const FrameBuffer frame = lit(g, 0.5f, [](int, int) { return 1.0f; });
  std::vector<float> length(g.pixels());
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) length[size_t(y) * kW + x] = x < kW / 2 ? 1.0f : 3.0f;
  AtrousOptions o = fix_only(8.0f);
  o.history_fix_min_length = 1.5f;
  AtrousFilter filter(o);
  FrameBuffer fixed;
  filter.apply(frame, g, fixed, AtrousHistory{nullptr, length.data()});
  const FrameBuffer off = filtered(frame, g, length, 0.0f);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW / 2; ++x)
      for (int k = 0; k < 4; ++k) {
        const size_t i = 4 * (size_t(y) * kW + x) + k;
        ASSERT_EQ(fixed.rgba[i], off.rgba[i]) << x << "," << y;
      }
  const double before = mean_square_error(off, 0.5f, kW / 2 + 8, kW - 2, 2, kH - 2);
  const double after = mean_square_error(fixed, 0.5f, kW / 2 + 8, kW - 2, 2, kH - 2);
  EXPECT_LT(after, before / 4.0) << "before " << before << " after " << after;
}

// Stride 0 takes the stride from the image height, one pixel per 180 rows (the door's lip grows with the
// image); a stride given is kept.
TEST(HistoryFix, StrideFromTheImageHeight) {
  EXPECT_EQ(history_fix_stride_for_height(108), 1);
  EXPECT_EQ(history_fix_stride_for_height(180), 1);
  EXPECT_EQ(history_fix_stride_for_height(269), 1);
  EXPECT_EQ(history_fix_stride_for_height(270), 2);
  EXPECT_EQ(history_fix_stride_for_height(360), 2);
  EXPECT_EQ(history_fix_stride_for_height(720), 4);
  EXPECT_EQ(history_fix_stride_for_height(1080), 6);
  EXPECT_EQ(history_fix_stride_for_height(1), 1);
  AtrousOptions o;
  o.history_fix_frames = 6.0f;
  EXPECT_EQ(o.history_fix_stride, 0.0f) << "the default is the height's";
  EXPECT_EQ(history_fix_params(o, 640, 360, true).stride, 2.0f);
  EXPECT_EQ(history_fix_params(o, 320, 180, true).stride, 1.0f);
  o.history_fix_stride = 3.0f;
  EXPECT_EQ(history_fix_params(o, 320, 180, true).stride, 3.0f);
}

// A short history everywhere, no noise, light 1 on one side of an edge and 5 on the other: each side keeps
// its own light exactly, whether the edge is a depth step, a fold (normals at right angles) or another entity
// at the same depth and normal.
class HistoryFixEdge : public ::testing::TestWithParam<int> {};

TEST_P(HistoryFixEdge, IsNotCrossed) {
  GBuffer g = wall();
  for (int y = 0; y < kH; ++y)
    for (int x = kW / 2; x < kW; ++x) {
      const size_t p = size_t(y) * kW + x;
      if (GetParam() == 0) g.depth[p] = g.prev_depth[p] = 100.0f;  // a silhouette
      if (GetParam() == 1) g.normal[3 * p] = 1.0f, g.normal[3 * p + 2] = 0.0f;
      if (GetParam() == 2) g.id[p] = 3;
    }
  const FrameBuffer frame = lit(g, 0.0f, [](int x, int) { return x < kW / 2 ? 1.0f : 5.0f; });
  const std::vector<float> length(g.pixels(), 1.0f);
  const FrameBuffer out = filtered(frame, g, length, 8.0f);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const float expected = (x < kW / 2 ? 1.0f : 5.0f) * 0.5f;
      ASSERT_NEAR(out.rgba[4 * (size_t(y) * kW + x)], expected, 1e-5f) << x << "," << y;
    }
  // The same light across no edge at all does blur (the test can fail): the wall's pixels next to the step.
  const FrameBuffer plain = filtered(frame, wall(), length, 8.0f);
  EXPECT_GT(plain.rgba[4 * (size_t(kH / 2) * kW + kW / 2 - 1)], 0.5f * 1.5f);
}

INSTANTIATE_TEST_SUITE_P(DepthNormalId, HistoryFixEdge, ::testing::Values(0, 1, 2));

// A NaN and an Inf sample in a short-history region: they stay where they are, every other pixel is finite
// and keeps the (noise-free) light; a pixel with no history (length 0) is copied.
TEST(HistoryFix, NanAndInfNeverSpread) {
  const GBuffer g = wall();
  FrameBuffer frame = lit(g, 0.0f, [](int, int) { return 1.0f; });
  const size_t nan_pixel = size_t(10) * kW + 10, inf_pixel = size_t(20) * kW + 30;
  frame.rgba[4 * nan_pixel + 1] = std::numeric_limits<float>::quiet_NaN();
  frame.rgba[4 * inf_pixel] = std::numeric_limits<float>::infinity();
  std::vector<float> length(g.pixels(), 1.0f);
  const size_t no_history = size_t(5) * kW + 40;
  length[no_history] = 0.0f;
  frame.rgba[4 * no_history] = 0.25f;  // what the reprojection shows where nothing entered the history
  const FrameBuffer out = filtered(frame, g, length, 8.0f);
  for (size_t p = 0; p < g.pixels(); ++p) {
    if (p == nan_pixel || p == inf_pixel) continue;
    for (int k = 0; k < 3; ++k) ASSERT_TRUE(std::isfinite(out.rgba[4 * p + k])) << p;
    if (p == no_history) continue;
    ASSERT_NEAR(out.rgba[4 * p + 1], 0.5f, 1e-5f) << p;  // green: the no-history pixel's red is its own
  }
  EXPECT_FLOAT_EQ(out.rgba[4 * no_history], 0.25f);
  EXPECT_TRUE(std::isnan(out.rgba[4 * nan_pixel + 1]));
}

// With the variance guide's planes (variance in alpha), the fix filters the variance with the weights
// squared: on a flat, uniform region of one-frame histories, an interior pixel's variance becomes
// v * (sum of the B3 spline's squared weights)^2, the variance of the weighted mean of 25 independent taps.
TEST(HistoryFix, VarianceFollowsTheBlur) {
  const GBuffer g = wall();
  std::vector<float> geometry(4 * g.pixels()), in(4 * g.pixels()), out(4 * g.pixels());
  std::vector<float> length(g.pixels(), 1.0f);
  for (size_t p = 0; p < g.pixels(); ++p) {
    k_atrous_pack_geometry(g.depth.data(), g.normal.data(), geometry.data(), static_cast<kint>(p));
    in[4 * p] = in[4 * p + 1] = in[4 * p + 2] = 1.0f;
    in[4 * p + 3] = 0.2f;
  }
  AtrousOptions o = fix_only(8.0f);
  const KHistoryFixParams p = history_fix_params(o, kW, kH, true);
  const int x = kW / 2, y = kH / 2;  // 6 pixels from any tap to the border
  k_svgf_history_fix_pixel(in.data(), out.data(), geometry.data(), g.id.data(), length.data(), &p, x, y);
  const double spline_squares = 0.375 * 0.375 + 2 * 0.25 * 0.25 + 2 * 0.0625 * 0.0625;
  const size_t c = size_t(y) * kW + x;
  EXPECT_NEAR(out[4 * c], 1.0f, 1e-6f);
  EXPECT_NEAR(out[4 * c + 3], 0.2 * spline_squares * spline_squares, 1e-6);
  // Unguided, alpha passes through.
  const KHistoryFixParams unguided = history_fix_params(o, kW, kH, false);
  k_svgf_history_fix_pixel(in.data(), out.data(), geometry.data(), g.id.data(), length.data(), &unguided, x, y);
  EXPECT_FLOAT_EQ(out[4 * c + 3], 0.2f);
}
