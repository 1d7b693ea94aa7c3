// The a-trous filter (kernel/atrous.h through core/atrous_filter.h): it removes noise within a surface,
// keeps the mean, does not leak across a geometric edge, keeps textures (albedo) sharp, and leaves out
// samples that are not finite.
#include <stdexcept>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "cohort/core/atrous_filter.h"

using namespace cohort::core;

namespace {

constexpr int kW = 64, kH = 48;

// Two walls meeting at x = kW/2 (normals +x and +y), both at depth 10, albedo 0.5 everywhere.
GBuffer two_walls() {
  GBuffer g;
  g.resize(kW, kH);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const size_t p = size_t(y) * kW + x;
      g.depth[p] = 10.0f;
      g.normal[3 * p + (x < kW / 2 ? 0 : 1)] = 1.0f;
      for (int k = 0; k < 3; ++k) g.albedo[3 * p + k] = 0.5f;
      g.id[p] = 0;
    }
  return g;
}

// Left wall lit to `left`, right wall to `right`, times (1 + uniform noise of +-noise).
FrameBuffer noisy(float left, float right, float noise, unsigned seed) {
  FrameBuffer f;
  f.resize(kW, kH);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-noise, noise);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const float v = (x < kW / 2 ? left : right) * (1.0f + u(rng));
      float* c = f.rgba.data() + 4 * (size_t(y) * kW + x);
      c[0] = c[1] = c[2] = v;
      c[3] = 1.0f;
    }
  return f;
}

struct Stats {
  double mean = 0.0, stddev = 0.0;
};
Stats column_stats(const FrameBuffer& f, int x0, int x1) {
  double sum = 0.0, sum2 = 0.0;
  int n = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = x0; x < x1; ++x) {
      const double v = f.rgba[4 * (size_t(y) * kW + x)];
      sum += v, sum2 += v * v, ++n;
    }
  const double mean = sum / n;
  return {mean, std::sqrt(std::max(sum2 / n - mean * mean, 0.0))};
}

AtrousOptions with(int passes, AtrousGuide guide) {
  AtrousOptions o;
  o.passes = passes;
  o.guide = guide;
  return o;
}

const AtrousGuide kGuides[] = {AtrousGuide::variance, AtrousGuide::variance_of_mean, AtrousGuide::fixed};

}  // namespace

TEST(AtrousFilter, SmoothsNoiseWithinASurfaceAndKeepsItsMean) {
  for (AtrousGuide guide : kGuides) {
  SCOPED_TRACE(atrous_guide_name(guide));
  const GBuffer g = two_walls();
  const FrameBuffer in = noisy(1.0f, 1.0f, 0.5f, 1);
  FrameBuffer out;
  AtrousFilter(with(3, guide)).apply(in, g, out);
  const Stats before = column_stats(in, 4, kW / 2 - 4), after = column_stats(out, 4, kW / 2 - 4);
  EXPECT_LT(after.stddev, 0.3 * before.stddev) << "before " << before.stddev << ", after " << after.stddev;
  EXPECT_NEAR(after.mean, before.mean, 0.03 * before.mean);
  }
}

TEST(AtrousFilter, DoesNotLeakAcrossAGeometricEdge) {
  for (AtrousGuide guide : kGuides) {
  SCOPED_TRACE(atrous_guide_name(guide));
  const GBuffer g = two_walls();
  const FrameBuffer in = noisy(1.0f, 0.05f, 0.3f, 2);
  FrameBuffer out;
  AtrousFilter(with(3, guide)).apply(in, g, out);
  // The columns right next to the edge keep their own wall's level.
  const Stats left = column_stats(out, kW / 2 - 1, kW / 2), right = column_stats(out, kW / 2, kW / 2 + 1);
  EXPECT_NEAR(left.mean, 1.0, 0.08);
  EXPECT_NEAR(right.mean, 0.05, 0.01);
  }
}

TEST(AtrousFilter, KeepsTexturesSharpThroughTheAlbedo) {
  // One wall, uniform light 1, a checkerboard albedo of 0.1 and 0.9: the image is the texture itself.
  GBuffer g = two_walls();
  FrameBuffer in;
  in.resize(kW, kH);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const size_t p = size_t(y) * kW + x;
      g.normal[3 * p] = 1.0f, g.normal[3 * p + 1] = 0.0f;
      const float a = ((x / 2 + y / 2) & 1) ? 0.9f : 0.1f;
      for (int k = 0; k < 3; ++k) g.albedo[3 * p + k] = a, in.rgba[4 * p + k] = a;
      in.rgba[4 * p + 3] = 1.0f;
    }
  for (AtrousGuide guide : kGuides) {
    FrameBuffer out;
    AtrousFilter(with(1, guide)).apply(in, g, out);
    for (size_t i = 0; i < in.rgba.size(); ++i)
      ASSERT_NEAR(out.rgba[i], in.rgba[i], 1e-4f) << "value " << i << " " << atrous_guide_name(guide);
  }
}

TEST(AtrousFilter, PassesGrowWithTheImageHeight) {
  EXPECT_EQ(atrous_passes_for_height(108), 1);
  EXPECT_EQ(atrous_passes_for_height(360), 1);
  EXPECT_EQ(atrous_passes_for_height(480), 2);
  EXPECT_EQ(atrous_passes_for_height(720), 3);
  EXPECT_EQ(atrous_passes_for_height(1080), 3);
  EXPECT_EQ(atrous_passes_for_height(2160), 4);
  EXPECT_EQ(atrous_passes_for_height(100000), 5);
}

TEST(AtrousFilter, LeavesOutSamplesThatAreNotFinite) {
  const GBuffer g = two_walls();
  FrameBuffer in = noisy(1.0f, 1.0f, 0.2f, 3);
  in.rgba[4 * (10 * kW + 10)] = std::numeric_limits<float>::quiet_NaN();
  in.rgba[4 * (20 * kW + 12) + 1] = std::numeric_limits<float>::infinity();
  for (AtrousGuide guide : kGuides) {
    FrameBuffer out;
    AtrousFilter(with(1, guide)).apply(in, g, out);
    for (float v : out.rgba) ASSERT_TRUE(std::isfinite(v)) << atrous_guide_name(guide);
    EXPECT_NEAR(out.rgba[4 * (10 * kW + 10)], 1.0f, 0.15f) << "a NaN pixel shows its neighbourhood";
  }
}

TEST(AtrousFilter, GuidesAreNamedOrRefused) {
  EXPECT_EQ(parse_atrous_guide("variance"), AtrousGuide::variance);
  EXPECT_EQ(parse_atrous_guide("fixed"), AtrousGuide::fixed);
  EXPECT_EQ(parse_atrous_guide("variance-of-mean"), AtrousGuide::variance_of_mean);
  EXPECT_STREQ(atrous_guide_name(AtrousGuide::variance_of_mean), "variance-of-mean");
  EXPECT_STREQ(atrous_guide_name(AtrousGuide::fixed), "fixed");
  EXPECT_THROW(parse_atrous_guide("svgf"), std::invalid_argument);
}

TEST(AtrousFilter, RefusesANormalPowerThatIsNotAPowerOfTwo) {
  const GBuffer g = two_walls();
  const FrameBuffer in = noisy(1.0f, 1.0f, 0.2f, 3);
  FrameBuffer out;
  AtrousOptions options;
  options.normal_power = 48;
  EXPECT_THROW(AtrousFilter(options).apply(in, g, out), std::invalid_argument);
  options.normal_power = 16;
  EXPECT_NO_THROW(AtrousFilter(options).apply(in, g, out));
}
