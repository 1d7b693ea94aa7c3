#include "cohort/core/band_buffer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "cohort/core/half_float.h"

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
