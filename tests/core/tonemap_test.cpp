#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "cohort/core/tonemap.h"

using namespace cohort::core;

TEST(ToneMap, KnownValues) {
  EXPECT_FLOAT_EQ(apply_tone_curve(ToneCurve::reinhard, 1.0f, 0.0f), 0.5f);
  EXPECT_FLOAT_EQ(apply_tone_curve(ToneCurve::reinhard, 3.0f, 0.0f), 0.75f);
  EXPECT_NEAR(apply_tone_curve(ToneCurve::reinhard, 4.0f, 4.0f), 1.0f, 1e-6);  // extended: white maps to 1
  EXPECT_NEAR(apply_tone_curve(ToneCurve::aces, 1.0f, 0.0f), 2.54f / 3.16f, 1e-6);
  EXPECT_NEAR(apply_tone_curve(ToneCurve::uncharted2, 5.6f, 11.2f), 1.0f, 1e-6);
  EXPECT_FLOAT_EQ(apply_tone_curve(ToneCurve::gamma, 0.25f, 0.0f), 0.25f);
  EXPECT_FLOAT_EQ(apply_tone_curve(ToneCurve::gamma, 7.0f, 0.0f), 1.0f);
  EXPECT_NEAR(encode_display(0.5f, false), std::pow(0.5f, 1.0f / 2.2f), 1e-6);
  EXPECT_NEAR(encode_display(0.5f, true), 0.735357f, 1e-5);
  EXPECT_FLOAT_EQ(encode_display(0.002f, true), 12.92f * 0.002f);
}

TEST(ToneMap, EveryCurveIsMonotoneAndBounded) {
  for (ToneCurve c : {ToneCurve::gamma, ToneCurve::reinhard, ToneCurve::aces, ToneCurve::uncharted2}) {
    float previous = 0.0f;
    for (float x = 0.0f; x < 64.0f; x += 0.01f) {
      const float y = apply_tone_curve(c, x, 11.2f);
      EXPECT_GE(y, previous - 1e-7f) << to_string(c) << " at " << x;
      EXPECT_GE(y, 0.0f);
      EXPECT_LE(y, 1.0f);
      previous = y;
    }
    EXPECT_EQ(apply_tone_curve(c, 0.0f, 11.2f), 0.0f) << to_string(c);
    EXPECT_EQ(apply_tone_curve(c, -1.0f, 11.2f), 0.0f) << to_string(c);
    EXPECT_EQ(apply_tone_curve(c, std::numeric_limits<float>::quiet_NaN(), 11.2f), 0.0f) << to_string(c);
  }
}

TEST(ToneMap, FrameToRgba8WithExposure) {
  FrameBuffer fb;
  fb.resize(2, 1);
  fb.rgba = {0.25f, 0.5f, 1.0f, 1.0f, std::numeric_limits<float>::quiet_NaN(), -3.0f, 1e9f, 0.0f};
  ToneMapOptions o;
  o.curve = ToneCurve::gamma;
  o.exposure_ev = 1.0;  // x2
  const auto px = tone_map(fb, o);
  ASSERT_EQ(px.size(), 8u);
  EXPECT_EQ(px[0], static_cast<uint8_t>(std::lround(255.0 * std::pow(0.5, 1.0 / 2.2))));
  EXPECT_EQ(px[1], 255);
  EXPECT_EQ(px[2], 255);
  EXPECT_EQ(px[3], 255);
  EXPECT_EQ(px[4], 0);
  EXPECT_EQ(px[5], 0);
  EXPECT_EQ(px[6], 255);
  EXPECT_EQ(px[7], 255);
}

TEST(ToneMap, DarkValuesKeepTheirSteps) {
  FrameBuffer fb;
  fb.resize(2, 1);
  fb.rgba = {0.0005f, 0.0005f, 0.0005f, 1.0f, 0.001f, 0.001f, 0.001f, 1.0f};
  ToneMapOptions o;
  o.curve = ToneCurve::gamma;
  const auto px = tone_map(fb, o);
  EXPECT_EQ(px[0], static_cast<uint8_t>(std::lround(255.0 * std::pow(0.0005, 1.0 / 2.2))));
  EXPECT_LT(px[0], px[4]);
}

TEST(ToneMap, ExactEncodingRoundsEachValueAndBlacksOutNonFinite) {
  FrameBuffer fb;
  fb.resize(2, 1);
  const float inf = std::numeric_limits<float>::infinity();
  fb.rgba = {0.0005f, 0.3f, 7.0f, 1.0f, inf, std::numeric_limits<float>::quiet_NaN(), -2.0f, 1.0f};
  ToneMapOptions o;
  o.exposure_ev = std::log2(1.5);
  o.exact_encoding = true;
  const auto px = tone_map(fb, o);
  auto expected = [](float v) {  // ACES, gamma 2.2, rounded half up: what `cohort render` has always written
    const float x = v * 1.5f;
    const float y = std::clamp((x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f), 0.0f, 1.0f);
    return static_cast<uint8_t>(std::pow(y, 1.0f / 2.2f) * 255.0f + 0.5f);
  };
  EXPECT_EQ(px[0], expected(0.0005f));
  EXPECT_EQ(px[1], expected(0.3f));
  EXPECT_EQ(px[2], expected(7.0f));
  EXPECT_EQ(px[3], 255);
  EXPECT_EQ(px[4], 0) << "+infinity is black when encoding exactly";
  EXPECT_EQ(px[5], 0);
  EXPECT_EQ(px[6], 0);
}

TEST(ToneMap, ParsesNames) {
  EXPECT_EQ(parse_tone_curve("aces"), ToneCurve::aces);
  EXPECT_EQ(parse_tone_curve("filmic"), ToneCurve::uncharted2);
  EXPECT_THROW(parse_tone_curve("drago"), std::invalid_argument);
}
