// SVGF's variance guide (kernel/svgf.h, through core/reprojection.h and core/atrous_filter.h): the
// history's luminance moments give each pixel's temporal variance exactly as a brute-force computation
// over its frames does, a short history gets the spatial estimate, NaN and Inf samples never enter the
// moments, and the guided filter removes noise in a flat region while it keeps a lighting edge that the
// fixed luminance stop blurs.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "cohort/core/atrous_filter.h"
#include "cohort/core/frame_post.h"
#include "cohort/core/reprojection.h"
#include "still_wall.h"

using namespace cohort::core;

namespace {

constexpr int kW = 48, kH = 32;

// A flat wall facing the camera at depth 10 (world, id 0), nothing moving; a checkerboard albedo of 0.25
// and 0.75 in one channel, so illumination (colour over albedo) differs from colour.
GBuffer still_wall() {
  GBuffer g = cohort::test::still_wall(kW, kH, 0.5f);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) g.albedo[3 * (size_t(y) * kW + x)] = ((x / 3 + y / 3) & 1) ? 0.75f : 0.25f;
  return g;
}

// Each pixel's light level times (1 + uniform noise of +-noise), times its albedo.
FrameBuffer lit_frame(const GBuffer& g, std::mt19937& rng, float noise, float left, float right) {
  std::uniform_real_distribution<float> u(-noise, noise);
  FrameBuffer f;
  f.resize(kW, kH);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const size_t p = size_t(y) * kW + x;
      const float light = (x < kW / 2 ? left : right) * (1.0f + u(rng));
      for (int k = 0; k < 3; ++k) f.rgba[4 * p + k] = light * g.albedo[3 * p + k];
      f.rgba[4 * p + 3] = 1.0f;
    }
  return f;
}

double illumination_luminance(const FrameBuffer& f, const GBuffer& g, size_t p) {
  double rgb[3];
  for (int k = 0; k < 3; ++k) rgb[k] = f.rgba[4 * p + k] / std::max(g.albedo[3 * p + k], 0.01f);
  return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
}

ReprojectionOptions with_moments() {
  ReprojectionOptions o;
  o.luminance_moments = true;
  return o;
}

struct Stats {
  double mean = 0.0, stddev = 0.0;
};
Stats region(const FrameBuffer& f, int x0, int x1, int y0, int y1) {
  double sum = 0.0, sum2 = 0.0;
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const double v = f.rgba[4 * (size_t(y) * kW + x) + 1];  // green: albedo 0.5 everywhere
      sum += v, sum2 += v * v, ++n;
    }
  const double mean = sum / n;
  return {mean, std::sqrt(std::max(sum2 / n - mean * mean, 0.0))};
}

}  // namespace

TEST(SvgfVariance, TemporalMomentsMatchABruteForceVariance) {
  TemporalReprojection r(with_moments());
  const GBuffer g = still_wall();
  AtrousOptions options;
  options.guide = AtrousGuide::variance;
  AtrousFilter filter(options);
  options.guide = AtrousGuide::variance_of_mean;
  AtrousFilter of_mean(options);
  FrameBuffer filtered;
  std::mt19937 rng(3);
  const size_t pixels = size_t(kW) * kH;
  std::vector<double> sum(pixels, 0.0), sum2(pixels, 0.0);
  for (int n = 1; n <= 12; ++n) {
    const FrameBuffer f = lit_frame(g, rng, 0.6f, 1.0f, 3.0f);
    for (size_t p = 0; p < pixels; ++p) {
      const double l = illumination_luminance(f, g, p);
      sum[p] += l, sum2[p] += l * l;
    }
    r.accumulate(f, g);
    filter.apply(r.image(), g, filtered, AtrousHistory{r.luminance_moments().data(), r.history_length().data()});
    of_mean.apply(r.image(), g, filtered, AtrousHistory{r.luminance_moments().data(), r.history_length().data()});
    ASSERT_EQ(r.luminance_moments().size(), 2 * pixels);
    for (size_t p = 0; p < pixels; ++p) {
      const double mean = sum[p] / n, variance = sum2[p] / n - mean * mean;
      const double m1 = r.luminance_moments()[2 * p], m2 = r.luminance_moments()[2 * p + 1];
      ASSERT_NEAR(m1, mean, 1e-5 * sum2[p] / n + 1e-6) << "frame " << n << " pixel " << p;
      ASSERT_NEAR(m2 - m1 * m1, variance, 1e-5 * sum2[p] / n + 1e-6) << "frame " << n << " pixel " << p;
      // From 4 frames on, the filter's variance is the temporal one (over n: the variance of the mean).
      if (n >= 4) {
        ASSERT_NEAR(filter.estimated_variance()[p], variance, 1e-5 * sum2[p] / n + 1e-6) << "frame " << n;
        ASSERT_NEAR(of_mean.estimated_variance()[p], variance / n, 1e-5 * sum2[p] / n + 1e-6) << "frame " << n;
      }
    }
  }
}

// With fewer than short_history frames, the variance comes from the 7x7 neighbourhood's moments on the same
// surface, boosted by short_history / length.
TEST(SvgfVariance, ShortHistoryGetsTheSpatialEstimate) {
  const GBuffer g = still_wall();
  std::mt19937 rng(4);
  const FrameBuffer f = lit_frame(g, rng, 0.5f, 2.0f, 2.0f);
  TemporalReprojection r(with_moments());
  r.accumulate(f, g);
  AtrousOptions options;
  options.guide = AtrousGuide::variance;
  options.short_history = 4.0f;  // SVGF's window (the default is 2): a one-frame history is boosted 4x
  AtrousFilter filter(options);
  FrameBuffer out;
  for (bool history : {true, false}) {
    filter.apply(r.image(), g, out,
                 history ? AtrousHistory{r.luminance_moments().data(), r.history_length().data()} : AtrousHistory{});
    for (int y = 3; y < kH - 3; ++y)
      for (int x = 3; x < kW - 3; ++x) {
        double s = 0.0, s2 = 0.0;
        for (int dy = -3; dy <= 3; ++dy)
          for (int dx = -3; dx <= 3; ++dx) {
            const double l = illumination_luminance(f, g, size_t(y + dy) * kW + (x + dx));
            s += l, s2 += l * l;
          }
        const double mean = s / 49.0, expected = options.short_history * (s2 / 49.0 - mean * mean);
        ASSERT_NEAR(filter.estimated_variance()[size_t(y) * kW + x], expected, 1e-3 * expected) << x << "," << y;
      }
  }
}

TEST(SvgfVariance, NonFiniteSamplesNeverEnterTheMoments) {
  TemporalReprojection r(with_moments());
  const GBuffer g = still_wall();
  const float bad[] = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                       -std::numeric_limits<float>::infinity()};
  std::mt19937 rng(11);
  const size_t pixels = size_t(kW) * kH;
  std::vector<double> sum(pixels, 0.0), sum2(pixels, 0.0);
  std::vector<int> good(pixels, 0);
  HostFramePost post([] {
    FramePostOptions o;
    o.atrous = true;
    o.atrous_options.guide = AtrousGuide::variance;
    o.atrous_options.passes = 2;
    return o;
  }());
  for (int n = 0; n < 10; ++n) {
    FrameBuffer f = lit_frame(g, rng, 0.5f, 1.0f, 2.0f);
    for (size_t p = 0; p < pixels; ++p) {
      // Every third pixel every other frame, and the whole first row in frame 0 (no history yet).
      const bool poison = (p % 3 == size_t(n % 3) && n % 2 == 0) || (n == 0 && p < size_t(kW));
      if (poison) {
        f.rgba[4 * p + size_t(n % 3)] = bad[n % 3];
        continue;
      }
      const double l = illumination_luminance(f, g, p);
      sum[p] += l, sum2[p] += l * l;
      ++good[p];
    }
    r.accumulate(f, g);
    post.process(f, g, kEveryPixel);
    for (float v : r.luminance_moments()) ASSERT_TRUE(std::isfinite(v)) << "frame " << n;
    for (float v : post.image().rgba) ASSERT_TRUE(std::isfinite(v)) << "frame " << n;
  }
  for (size_t p = 0; p < pixels; ++p) {
    const double mean = sum[p] / good[p], variance = sum2[p] / good[p] - mean * mean;
    const double m1 = r.luminance_moments()[2 * p], m2 = r.luminance_moments()[2 * p + 1];
    EXPECT_NEAR(m1, mean, 1e-5 * sum2[p] / good[p]) << p;
    EXPECT_NEAR(m2 - m1 * m1, variance, 1e-5 * sum2[p] / good[p]) << p;
  }
  // A finite sample whose luminance's square overflows a float (a firefly over a black albedo) enters the
  // colour history but not the moments.
  FrameBuffer f = lit_frame(g, rng, 0.5f, 1.0f, 2.0f);
  f.rgba[4 * 5] = 1e36f;
  const float m1_before = r.luminance_moments()[2 * 5], m2_before = r.luminance_moments()[2 * 5 + 1];
  r.accumulate(f, g);
  for (float v : r.luminance_moments()) ASSERT_TRUE(std::isfinite(v));
  EXPECT_FLOAT_EQ(r.luminance_moments()[2 * 5], m1_before);
  EXPECT_FLOAT_EQ(r.luminance_moments()[2 * 5 + 1], m2_before);
}

// A lighting edge on one flat wall (a shadow's border: same normal and depth both sides), light 1 on the
// left and 3 on the right with +-50% noise, after 8 still frames of reprojection. The guided filter (3
// passes, sigma 2 standard deviations of the per-frame noise) must take most of the noise out of the flat
// region and keep the edge; the fixed luminance stop, at its default scale, pulls the two sides together.
TEST(SvgfVariance, SmoothsAFlatNoisyRegionMoreThanItBlursASharpEdge) {
  const GBuffer g = still_wall();
  std::mt19937 rng(21);
  TemporalReprojection r(with_moments());
  for (int n = 0; n < 8; ++n) r.accumulate(lit_frame(g, rng, 0.5f, 1.0f, 3.0f), g);
  const AtrousHistory history{r.luminance_moments().data(), r.history_length().data()};
  const auto measure = [&](AtrousGuide guide, double* noise_ratio, double* edge_blur) {
    AtrousOptions options;
    options.guide = guide;
    options.passes = 3;
    options.variance_sigma = 2.0f;
    options.color_sigma = 2.0f;
    FrameBuffer out;
    AtrousFilter(options).apply(r.image(), g, out, history);
    const Stats before = region(r.image(), 2, kW / 2 - 8, 2, kH - 2), after = region(out, 2, kW / 2 - 8, 2, kH - 2);
    *noise_ratio = after.stddev / before.stddev;
    EXPECT_NEAR(after.mean, 0.5, 0.02) << "the flat region keeps its level (" << atrous_guide_name(guide) << ")";
    // Green is light * 0.5: 0.5 on the left, 1.5 on the right; the columns on either side of the edge.
    const double left = region(out, kW / 2 - 1, kW / 2, 0, kH).mean, right = region(out, kW / 2, kW / 2 + 1, 0, kH).mean;
    *edge_blur = ((left - 0.5) + (1.5 - right)) / 2.0 / (1.5 - 0.5);
  };
  double variance_noise = 0, variance_blur = 0, fixed_noise = 0, fixed_blur = 0, mean_noise = 0, mean_blur = 0;
  measure(AtrousGuide::variance, &variance_noise, &variance_blur);
  measure(AtrousGuide::fixed, &fixed_noise, &fixed_blur);
  measure(AtrousGuide::variance_of_mean, &mean_noise, &mean_blur);
  RecordProperty("variance_noise_ratio", std::to_string(variance_noise));
  RecordProperty("variance_edge_blur", std::to_string(variance_blur));
  RecordProperty("fixed_noise_ratio", std::to_string(fixed_noise));
  RecordProperty("fixed_edge_blur", std::to_string(fixed_blur));
  std::printf("noise left (after / before): variance %.3f, of the mean %.3f, fixed %.3f; edge pulled in: variance "
              "%.3f, of the mean %.3f, fixed %.3f\n",
              variance_noise, mean_noise, fixed_noise, variance_blur, mean_blur, fixed_blur);
  // Measured: noise 0.072 of what reprojection left, edge pulled in by 0.043 of the step (fixed: 0.099, 0.402;
  // the variance guide at SVGF's sigma 4: 0.058, 0.117).
  EXPECT_LT(variance_noise, 0.15) << "the flat region keeps less than a sixth of its noise";
  EXPECT_LT(variance_blur, 0.08) << "the edge's two sides move by less than 8% of the step";
  EXPECT_LT(variance_blur, 0.25 * fixed_blur) << "the fixed stop blurs the lighting edge far more";
  EXPECT_LT(variance_noise, 2.0 * fixed_noise) << "and does not denoise much better";
  // The variance of the mean (8 frames: an eighth of the sample's) stops at the noise the mean still has:
  // measured 0.231 of the noise left, the edge moved by 0.002 of the step.
  EXPECT_LT(mean_noise, 0.4) << "the variance of the mean still takes most of the mean's noise out";
  EXPECT_LT(mean_blur, 0.02) << "and leaves the edge where it is";
}
