// The firefly clamp before the a-trous passes (kernel/firefly.h, AtrousOptions::firefly_factor): a lone pixel
// far brighter than its neighbours is scaled down to `factor` times the brightest of them; features two pixels
// wide, non-finite samples and dark pixels are left alone; in the filter it takes a 1-spp firefly out of the
// image it shows, and with the factor at 0 the firefly stays.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "cohort/core/atrous_filter.h"
#include "cohort/kernel/firefly.h"

using namespace cohort::core;

namespace {

constexpr int kW = 8, kH = 6;

// A grey field of luminance 1 (RGB 1, alpha 7 to see it copied).
std::vector<float> field() {
  std::vector<float> rgba(4 * kW * kH, 1.0f);
  for (int p = 0; p < kW * kH; ++p) rgba[4 * p + 3] = 7.0f;
  return rgba;
}

void set(std::vector<float>& rgba, int x, int y, float r, float g, float b) {
  float* c = rgba.data() + 4 * (y * kW + x);
  c[0] = r, c[1] = g, c[2] = b;
}

std::vector<float> clamp_all(const std::vector<float>& in, float factor) {
  std::vector<float> out(in.size(), -1.0f);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) k_firefly_clamp_pixel(in.data(), out.data(), kW, kH, factor, x, y);
  return out;
}

const float* at(const std::vector<float>& rgba, int x, int y) { return rgba.data() + 4 * (y * kW + x); }

}  // namespace

TEST(FireflyClamp, ScalesALonePixelDownToTheFactorTimesItsBrightestNeighbour) {
  std::vector<float> in = field();
  set(in, 3, 2, 100.0f, 50.0f, 20.0f);  // a firefly
  set(in, 4, 3, 2.0f, 2.0f, 2.0f);      // its brightest neighbour: luminance 2
  set(in, 0, 0, 40.0f, 40.0f, 40.0f);   // one in the corner, three neighbours of luminance 1
  const std::vector<float> out = clamp_all(in, 3.0f);
  const float* c = at(out, 3, 2);
  const float luminance = 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2];
  EXPECT_NEAR(luminance, 6.0f, 1e-4f);
  EXPECT_NEAR(c[0] / c[1], 2.0f, 1e-5f) << "the colour keeps its hue";
  EXPECT_NEAR(at(out, 0, 0)[0], 3.0f, 1e-5f);
  EXPECT_EQ(at(out, 3, 2)[3], 7.0f) << "alpha is copied";
  // Everything else, the bright neighbour included (its own brightest neighbour is the firefly), is unchanged.
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      if ((x == 3 && y == 2) || (x == 0 && y == 0)) continue;
      for (int k = 0; k < 4; ++k) ASSERT_EQ(at(out, x, y)[k], at(in, x, y)[k]) << x << "," << y;
    }
}

TEST(FireflyClamp, LeavesAFeatureTwoPixelsWideAlone) {
  std::vector<float> in = field();
  set(in, 3, 2, 100.0f, 100.0f, 100.0f);
  set(in, 4, 2, 90.0f, 90.0f, 90.0f);
  EXPECT_EQ(clamp_all(in, 3.0f), in);
}

TEST(FireflyClamp, LeavesNonFiniteAndDarkPixelsAloneAndIgnoresNonFiniteNeighbours) {
  std::vector<float> in = field();
  set(in, 2, 2, std::numeric_limits<float>::quiet_NaN(), 1.0f, 1.0f);
  set(in, 5, 2, -4.0f, -4.0f, -4.0f);
  set(in, 6, 4, std::numeric_limits<float>::infinity(), 0.0f, 0.0f);
  set(in, 3, 3, 10.0f, 10.0f, 10.0f);  // next to the NaN: its brightest finite neighbour has luminance 1
  const std::vector<float> out = clamp_all(in, 3.0f);
  EXPECT_TRUE(std::isnan(at(out, 2, 2)[0]));
  EXPECT_EQ(at(out, 5, 2)[0], -4.0f);
  EXPECT_TRUE(std::isinf(at(out, 6, 4)[0]));
  EXPECT_NEAR(at(out, 3, 3)[0], 3.0f, 1e-5f);
}

TEST(FireflyClamp, TakesAFireflyOutOfTheFilteredImageUnlessTurnedOff) {
  constexpr int w = 32, h = 24;
  GBuffer g;
  g.resize(w, h);
  FrameBuffer in;
  in.resize(w, h);
  for (int p = 0; p < w * h; ++p) {
    g.depth[p] = 10.0f;
    g.normal[3 * p + 2] = 1.0f;
    for (int k = 0; k < 3; ++k) g.albedo[3 * p + k] = 0.5f, in.rgba[4 * p + k] = 0.5f * (0.9f + 0.2f * ((p * 7) % 5) / 4.0f);
    in.rgba[4 * p + 3] = 1.0f;
  }
  const int firefly = 12 * w + 16;
  for (int k = 0; k < 3; ++k) in.rgba[4 * firefly + k] = 200.0f;
  AtrousOptions options;
  options.passes = 1;
  FrameBuffer clamped, kept;
  options.firefly_factor = 3.0f;
  AtrousFilter(options).apply(in, g, clamped);
  options.firefly_factor = 0.0f;
  AtrousFilter(options).apply(in, g, kept);
  EXPECT_LT(clamped.rgba[4 * firefly], 2.0f) << "at most 3x its neighbours' 0.55 before the passes";
  EXPECT_GT(kept.rgba[4 * firefly], 20.0f) << "the luminance stop keeps a lone firefly where nothing clamps it";
}
