#include "cohort/core/band_buffer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "cohort/core/convergence.h"
#include "cohort/core/half_float.h"
#include "cohort/kernel/band_pack.h"

using namespace cohort::core;

TEST(HalfFloat, KnownValuesConvertExactly) {
  EXPECT_EQ(float_to_half(0.0f), 0x0000);
  EXPECT_EQ(float_to_half(-0.0f), 0x8000);
  EXPECT_EQ(float_to_half(1.0f), 0x3c00);
  EXPECT_EQ(float_to_half(-2.0f), 0xc000);
  EXPECT_EQ(float_to_half(65504.0f), 0x7bff);                      // the largest half
  EXPECT_EQ(float_to_half(65520.0f), 0x7c00);                      // rounds up past it: infinity
  EXPECT_EQ(float_to_half(std::numeric_limits<float>::infinity()), 0x7c00);
  EXPECT_EQ(float_to_half(0x1p-24f), 0x0001);                      // the smallest subnormal
  EXPECT_EQ(float_to_half(0x1p-14f), 0x0400);                      // the smallest normal
  EXPECT_EQ(float_to_half(1.0f + 0x1p-11f), 0x3c00);               // a tie rounds to even (down)
  EXPECT_EQ(float_to_half(1.0f + 3 * 0x1p-11f), 0x3c02);           // a tie rounds to even (up)
  EXPECT_TRUE(std::isnan(half_to_float(float_to_half(std::numeric_limits<float>::quiet_NaN()))));
  EXPECT_EQ(half_to_float(0x7c00), std::numeric_limits<float>::infinity());
  EXPECT_EQ(half_to_float(0xfc00), -std::numeric_limits<float>::infinity());
  EXPECT_EQ(half_to_float(0x0001), 0x1p-24f);
  EXPECT_EQ(half_to_float(0x3555), 0.333251953125f);
}

TEST(HalfFloat, EveryHalfSurvivesTheRoundTripAndFloatsRoundToTheNearest) {
  for (uint32_t h = 0; h < 0x10000; ++h) {
    const float f = half_to_float(static_cast<uint16_t>(h));
    if (std::isnan(f)) continue;
    ASSERT_EQ(float_to_half(f), h) << std::hex << h;
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> exponent(-20.0f, 15.9f);
  for (int i = 0; i < 100000; ++i) {
    const float x = std::exp2(exponent(rng));
    const float back = half_to_float(float_to_half(x));
    const float ulp = x < 0x1p-14f ? 0x1p-24f : std::exp2(std::floor(std::log2(x)) - 10.0f);
    ASSERT_LE(std::abs(back - x), 0.5f * ulp) << x;
  }
}

TEST(BandBuffer, RowsStoredAsHalvesComeBackAsFloatsWithinHalfPrecision) {
  BandBuffer band(5, 4, BandFormat::rgb16f);
  EXPECT_EQ(band.bytes(), 5u * 4u * 6u);
  const float row[5 * 4] = {0.1f, 2.5f, 1000.0f, 0.3f, 0.0f, 1.0f, 70000.0f, 1.0f, 3.14159f, 0.001f, 1e-6f, 1.0f,
                            7.0f, 8.0f, 9.0f, 1.0f, 0.5f, 0.25f, 0.125f, 1.0f};
  band.store(2, 0, row, 5);
  FrameBuffer out;
  out.resize(5, 4);
  band.copy_rows_to(out, 1, 3);
  for (int x = 0; x < 5; ++x) {
    for (int k = 0; k < 3; ++k) {
      const float want = row[4 * x + k], got = out.row(2)[4 * x + k];
      if (want > 65504.0f) EXPECT_TRUE(std::isinf(got));
      else EXPECT_NEAR(got, want, std::max(want * 0x1p-11f, 0x1p-24f)) << x << "," << k;
    }
    EXPECT_EQ(out.row(2)[4 * x + 3], 1.0f);  // alpha is not carried: always 1
    EXPECT_EQ(out.row(1)[4 * x], 0.0f);      // a row nobody stored stays cleared
  }
  EXPECT_THROW(band.store(4, 0, row, 1), std::out_of_range);
  EXPECT_THROW(band.store(0, 1, row, 5), std::out_of_range);
  FrameBuffer wrong;
  wrong.resize(4, 4);
  EXPECT_THROW(band.copy_rows_to(wrong, 0, 1), std::invalid_argument);
}

TEST(BandBuffer, FloatRowsComeBackExactly) {
  BandBuffer band(2, 2, BandFormat::rgba32f);
  const float row[8] = {1e-30f, 123456.789f, -3.0f, 0.5f, 7.0f, 8.0f, 9.0f, 10.0f};
  band.store(1, 0, row, 2);
  FrameBuffer out;
  out.resize(2, 2);
  band.copy_rows_to(out, 0, 2);
  for (int i = 0; i < 8; ++i) EXPECT_EQ(out.row(1)[i], row[i]);
}

TEST(HalfFloat, RowConversionsAgreeWithTheScalarOnes) {
  // The row conversions may take a faster path (F16C); they must give the same halves and floats.
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> exponent(-30.0f, 20.0f);
  std::vector<float> rgba(4 * 1001);
  for (size_t i = 0; i < rgba.size(); ++i) rgba[i] = (i % 7 == 0 ? -1.0f : 1.0f) * std::exp2(exponent(rng));
  rgba[4] = std::numeric_limits<float>::infinity();
  rgba[9] = 0.0f;
  std::vector<uint16_t> rgb(3 * 1001);
  rgba32f_to_rgb16f(rgba.data(), rgb.data(), 1001);
  for (size_t p = 0; p < 1001; ++p)
    for (size_t k = 0; k < 3; ++k) ASSERT_EQ(rgb[3 * p + k], float_to_half(rgba[4 * p + k])) << p << "," << k;
  std::vector<float> back(4 * 1001);
  rgb16f_to_rgba32f(rgb.data(), back.data(), 1001);
  for (size_t p = 0; p < 1001; ++p) {
    for (size_t k = 0; k < 3; ++k) ASSERT_EQ(back[4 * p + k], half_to_float(rgb[3 * p + k])) << p << "," << k;
    ASSERT_EQ(back[4 * p + 3], 1.0f);
  }
}

// RGB9E5 (kernel/band_pack.h): the packing every producer uses and the host's decoder.
TEST(Rgb9e5, KnownValuesZeroClampsAndNonFinite) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  EXPECT_EQ(k_rgb9e5_encode(0.0f, 0.0f, 0.0f, 0.99f), 0u);  // zero stays zero whatever the dither
  EXPECT_EQ(k_rgb9e5_encode(-0.0f, -5.0f, 1e-30f, 0.5f), 0u);  // negatives clamp to 0, tiny values round to it
  const uint32_t one = k_rgb9e5_encode(1.0f, 1.0f, 1.0f, 0.99f);  // exact values ignore the dither
  for (uint32_t k = 0; k < 3; ++k) EXPECT_EQ(k_rgb9e5_channel(one, k), 1.0f);
  const uint32_t huge = k_rgb9e5_encode(1e30f, 2.0f * K_RGB9E5_MAX, K_RGB9E5_MAX, 0.99f);
  for (uint32_t k = 0; k < 3; ++k) EXPECT_EQ(k_rgb9e5_channel(huge, k), K_RGB9E5_MAX) << k;
  EXPECT_NE(huge, K_RGB9E5_NONFINITE);  // the largest finite pixel is not the reserved word
  for (float bad : {nan, inf, -inf}) {
    for (int at = 0; at < 3; ++at) {
      float c[3] = {0.5f, 2.0f, 3.0f};
      c[at] = bad;
      const uint32_t word = k_rgb9e5_encode(c[0], c[1], c[2], 0.3f);
      EXPECT_EQ(word, K_RGB9E5_NONFINITE);
      for (uint32_t k = 0; k < 3; ++k) EXPECT_TRUE(std::isnan(k_rgb9e5_channel(word, k))) << bad << " at " << at;
    }
  }
}

TEST(Rgb9e5, EveryChannelIsWithinOneStepOfTheBrightest) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> exponent(-20.0f, 15.9f), unit(0.0f, 1.0f);
  for (int i = 0; i < 200000; ++i) {
    const float c[3] = {std::exp2(exponent(rng)), std::exp2(exponent(rng)), std::exp2(exponent(rng))};
    const float top = std::max({c[0], c[1], c[2]});
    const float dither = unit(rng);
    const uint32_t word = k_rgb9e5_encode(c[0], c[1], c[2], dither);
    const uint32_t nearest = k_rgb9e5_encode(c[0], c[1], c[2], 0.5f);
    // A step is 2^(e-24) with the brightest channel's mantissa in (255.5, 511]: under top / 255.5 (one step
    // at most, rounding up or down; half of it to the nearest), and 2^-24 at the smallest exponent.
    const float step = std::max(top / 255.5f, 0x1p-24f);
    for (uint32_t k = 0; k < 3; ++k) {
      ASSERT_LT(std::fabs(k_rgb9e5_channel(word, k) - c[k]), step) << c[0] << " " << c[1] << " " << c[2];
      ASSERT_LE(std::fabs(k_rgb9e5_channel(nearest, k) - c[k]), 0.5f * step) << c[0] << " " << c[1] << " " << c[2];
    }
    // The brightest channel keeps 9 bits: relative error at most 1/511 rounded to the nearest (above the
    // smallest exponent's range).
    const uint32_t brightest = c[0] == top ? 0 : c[1] == top ? 1 : 2;
    if (top > 0x1p-16f) {
      ASSERT_LE(std::fabs(k_rgb9e5_channel(nearest, brightest) - top), top / 511.0f) << top;
    }
  }
}

// The dither makes the mean of many frames' encodings the input: a channel 1.4 steps high reads 1 step
// when rounded to the nearest (29 % low), and 1.4 on average when dithered by frame.
TEST(Rgb9e5, TheMeanOfManyDitheredEncodingsIsTheInput) {
  const float colours[][3] = {{1.0f, 0.0027f, 0.0f},      {300.0f, 1.3f, 0.07f},     {0.0031f, 0.0029f, 2e-6f},
                              {5e-5f, 0.75f, 0.017f},      {60000.0f, 65000.0f, 1.0f}, {0.2f, 0.2f, 0.2f}};
  constexpr int kFrames = 20000;
  for (const auto& c : colours) {
    double sum[3] = {0, 0, 0};
    for (uint32_t frame = 0; frame < kFrames; ++frame) {
      const uint32_t word = k_rgb9e5_encode(c[0], c[1], c[2], k_rgb9e5_dither(1234u, frame));
      for (uint32_t k = 0; k < 3; ++k) sum[k] += k_rgb9e5_channel(word, k);
    }
    const float top = std::max({c[0], c[1], c[2]});
    for (int k = 0; k < 3; ++k) {
      // A dithered channel's error is a step (under top / 255.5) times a centred Bernoulli variable: its mean
      // over N frames is within 5 standard deviations, step / (2 sqrt(N)) at most, of the input.
      const double bound = 5.0 * (top / 255.5) / (2.0 * std::sqrt(double(kFrames)));
      EXPECT_NEAR(sum[k] / kFrames, c[k], bound) << "channel " << k << " of " << c[0] << " " << c[1] << " " << c[2];
    }
  }
}

TEST(BandBuffer, Rgb9e5RowsComeBackWithinAStepAndNonFiniteAsNaN) {
  BandBuffer band(4, 3, BandFormat::rgb9e5);
  EXPECT_EQ(band.bytes(), 4u * 3u * 4u);
  EXPECT_EQ(band.row_bytes(), 16u);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float row[4 * 4] = {0.1f, 2.5f, 1000.0f, 0.3f, 0.0f, 0.0f, 0.0f, 1.0f, nan, 1.0f, 1.0f, 1.0f, 1e9f, 0.5f, 0.25f, 1.0f};
  band.store(1, 0, row, 4, 7);
  FrameBuffer out;
  out.resize(4, 3);
  band.copy_rows_to(out, 0, 3);
  EXPECT_NEAR(out.row(1)[2], 1000.0f, 1000.0f / 256.0f);
  EXPECT_NEAR(out.row(1)[1], 2.5f, 1000.0f / 256.0f);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(out.row(1)[4 + k], 0.0f);
  for (int k = 0; k < 3; ++k) EXPECT_TRUE(std::isnan(out.row(1)[8 + k]));  // the history's rejection sees it
  EXPECT_EQ(out.row(1)[12], K_RGB9E5_MAX);                                    // huge values clamp
  for (int x = 0; x < 4; ++x) {
    EXPECT_EQ(out.row(1)[4 * x + 3], 1.0f);  // alpha is not carried
    EXPECT_EQ(out.row(0)[4 * x], 0.0f);      // a row nobody stored stays cleared
  }
  // The dither counts pixels over the whole frame: a store at (x, y) packs as the bulk conversion from
  // pixel y * width + x does.
  uint32_t want[4];
  rgba32f_to_rgb9e5(row, want, 4, 1u * 4u, 7u);
  for (int x = 0; x < 4; ++x) EXPECT_EQ(static_cast<const uint32_t*>(band.row(1))[x], want[x]) << x;
  EXPECT_EQ(band_format_from_string("rgb9e5"), BandFormat::rgb9e5);
  EXPECT_EQ(std::string(to_string(BandFormat::rgb9e5)), "rgb9e5");
  EXPECT_THROW(band_format_from_string("r11g11b10f"), std::invalid_argument);
}

// Brigade's blend over 64 frames of a tinted HDR image, each frame stored in an RGB9E5 band with its own
// frame index: the image's mean does not drift from the input's, and each pixel's error shrinks with the
// frames, where rounding to the nearest keeps every pixel's rounding error however many frames are blended.
TEST(BandBuffer, Rgb9e5FramesBlendedByBrigadeKeepTheMeanImage) {
  const int w = 64, h = 32;
  FrameBuffer input;
  input.resize(w, h);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> exponent(-6.0f, 6.0f), tint(0.002f, 0.05f);
  for (size_t p = 0; p < size_t(w) * h; ++p) {
    const float bright = std::exp2(exponent(rng));
    // One bright channel, two dim ones: a coloured light's pixel, where a shared exponent is coarsest.
    for (int k = 0; k < 3; ++k) input.rgba[4 * p + k] = bright * (k == int(p % 3) ? 1.0f : tint(rng));
    input.rgba[4 * p + 3] = 1.0f;
  }
  AdaptiveConvergence dithered, nearest;
  BandBuffer band(w, h, BandFormat::rgb9e5);
  FrameBuffer frame, rounded;
  frame.resize(w, h);
  rounded.resize(w, h);
  for (uint32_t n = 0; n < 64; ++n) {
    for (int y = 0; y < h; ++y) band.store(y, 0, input.row(y), size_t(w), n);
    band.copy_rows_to(frame, 0, h);
    dithered.blend(frame, 1.0 / (n + 1.0));
    for (size_t p = 0; p < size_t(w) * h; ++p) {
      const float* c = &input.rgba[4 * p];
      const uint32_t word = k_rgb9e5_encode(c[0], c[1], c[2], 0.5f);
      for (uint32_t k = 0; k < 3; ++k) rounded.rgba[4 * p + k] = k_rgb9e5_channel(word, k);
    }
    nearest.blend(rounded, 1.0 / (n + 1.0));
  }
  // The image's drift (its sum against the input's), and the mean absolute error of the dim channels
  // relative to their pixel's brightest channel (a step is under 1/255.5 of it).
  auto drift = [&](const FrameBuffer& out) {
    double got = 0.0, want = 0.0;
    for (size_t p = 0; p < size_t(w) * h; ++p)
      for (int k = 0; k < 3; ++k) {
        got += out.rgba[4 * p + k];
        want += input.rgba[4 * p + k];
      }
    return got / want - 1.0;
  };
  auto dim_error = [&](const FrameBuffer& out) {
    double sum = 0.0;
    int count = 0;
    for (size_t p = 0; p < size_t(w) * h; ++p)
      for (int k = 0; k < 3; ++k)
        if (k != int(p % 3)) {
          sum += std::fabs(out.rgba[4 * p + k] - input.rgba[4 * p + k]) / input.rgba[4 * p + p % 3];
          ++count;
        }
    return sum / count;
  };
  EXPECT_LT(std::fabs(drift(dithered.image())), 1e-4) << "dithered: the blended image drifted";
  // Dithered, a dim channel's error after 64 frames is about 0.04 of a step (a Bernoulli mean's spread over 64
  // frames); rounded to the nearest, a quarter of a step, whatever the frame count.
  const double dithered_error = dim_error(dithered.image()), nearest_error = dim_error(nearest.image());
  EXPECT_LT(dithered_error, 0.1 / 255.5) << "dithered: the pixels did not converge to the input";
  EXPECT_GT(nearest_error, 3.0 * dithered_error) << "rounded to the nearest: no lasting error to show?";
}
