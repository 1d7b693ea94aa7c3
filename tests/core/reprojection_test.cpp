#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "cohort/core/band_buffer.h"
#include "cohort/core/reprojection.h"
#include "still_wall.h"

using namespace cohort::core;

namespace {

constexpr int kW = 16, kH = 8;

GBuffer still_wall() { return cohort::test::still_wall(kW, kH, 0.0f); }

FrameBuffer noise_frame(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(0.0f, 4.0f);
  FrameBuffer f;
  f.resize(kW, kH);
  for (size_t p = 0; p < static_cast<size_t>(kW * kH); ++p) {
    for (int k = 0; k < 3; ++k) f.rgba[4 * p + k] = u(rng);
    f.rgba[4 * p + 3] = 1.0f;
  }
  return f;
}

bool all_finite(const FrameBuffer& f) {
  for (float v : f.rgba)
    if (!std::isfinite(v)) return false;
  return true;
}

}  // namespace

TEST(Reprojection, StillViewIsThePlainAverageOfItsFrames) {
  ReprojectionOptions o;
  o.max_history = 64;
  TemporalReprojection r(o);
  const GBuffer g = still_wall();
  std::mt19937 rng(7);
  std::vector<double> sum(static_cast<size_t>(kW * kH * 4), 0.0);
  for (int n = 1; n <= 12; ++n) {
    const FrameBuffer f = noise_frame(rng);
    for (size_t i = 0; i < sum.size(); ++i) sum[i] += f.rgba[i];
    r.accumulate(f, g);
    for (size_t p = 0; p < static_cast<size_t>(kW * kH); ++p) {
      for (int k = 0; k < 3; ++k) ASSERT_NEAR(r.image().rgba[4 * p + k], sum[4 * p + k] / n, 1e-4) << "frame " << n;
      ASSERT_FLOAT_EQ(r.history_length()[p], static_cast<float>(n));
    }
  }
}

TEST(Reprojection, HistoryLengthStopsAtMaxHistory) {
  ReprojectionOptions o;
  o.max_history = 4;
  TemporalReprojection r(o);
  const GBuffer g = still_wall();
  std::mt19937 rng(3);
  for (int n = 0; n < 10; ++n) r.accumulate(noise_frame(rng), g);
  EXPECT_FLOAT_EQ(r.history_length()[5], 4.0f);
  // Now a constant frame: the blend moves a quarter of the way toward it.
  const float before = r.image().rgba[4 * 5];
  FrameBuffer c;
  c.resize(kW, kH);
  std::fill(c.rgba.begin(), c.rgba.end(), 100.0f);
  r.accumulate(c, g);
  EXPECT_NEAR(r.image().rgba[4 * 5], before + 0.25f * (100.0f - before), 1e-3);
}

// A camera panning 3 pixels per frame over a smooth ramp: the history follows the content, so the
// accumulated image is the current (shifted) ramp, not a blur of old positions, and history grows.
TEST(Reprojection, HistoryFollowsTheMotionVectors) {
  TemporalReprojection r;
  GBuffer g = still_wall();
  auto ramp = [](int shift) {
    FrameBuffer f;
    f.resize(kW, kH);
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x)
        for (int k = 0; k < 4; ++k) f.rgba[4 * (static_cast<size_t>(y) * kW + x) + k] = static_cast<float>(x + shift);
    return f;
  };
  r.accumulate(ramp(0), g);
  // Content moves left by 3 pixels: pixel x shows what was at x + 3, so motion = +3.
  for (size_t p = 0; p < g.pixels(); ++p) g.motion[2 * p] = 3.0f;
  r.accumulate(ramp(3), g);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const size_t p = static_cast<size_t>(y) * kW + x;
      EXPECT_NEAR(r.image().rgba[4 * p], static_cast<float>(x + 3), 1e-4) << x << "," << y;
      EXPECT_FLOAT_EQ(r.history_length()[p], x + 3 < kW ? 2.0f : 1.0f) << x << "," << y;  // off-screen: fresh
    }
}

// An object (id 5, in front) covered the left half and moves away: the background it uncovers has no
// valid history there (other id, other depth) and restarts from the fresh frame; the rest accumulates.
TEST(Reprojection, DisocclusionRestartsTheUncoveredBackground) {
  TemporalReprojection r;
  GBuffer g = still_wall();
  FrameBuffer first;
  first.resize(kW, kH);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const size_t p = static_cast<size_t>(y) * kW + x;
      const bool object = x < kW / 2;
      g.id[p] = object ? 6u : 0u;
      g.depth[p] = g.prev_depth[p] = object ? 2.0f : 10.0f;
      for (int k = 0; k < 3; ++k) first.rgba[4 * p + k] = object ? 50.0f : 1.0f;
      first.rgba[4 * p + 3] = 1.0f;
    }
  r.accumulate(first, g);
  const GBuffer background = still_wall();
  FrameBuffer second;
  second.resize(kW, kH);
  std::fill(second.rgba.begin(), second.rgba.end(), 3.0f);
  r.accumulate(second, background);
  for (int x = 0; x < kW; ++x) {
    const size_t p = static_cast<size_t>(2) * kW + x;
    if (x < kW / 2) {
      EXPECT_FLOAT_EQ(r.image().rgba[4 * p], 3.0f) << "uncovered pixel " << x << " kept the object's colour";
      EXPECT_FLOAT_EQ(r.history_length()[p], 1.0f);
    } else {
      EXPECT_FLOAT_EQ(r.image().rgba[4 * p], 2.0f) << "background pixel " << x;
      EXPECT_FLOAT_EQ(r.history_length()[p], 2.0f);
    }
  }
}

// A moving pixel's history is clamped to the fresh neighbourhood: a stale bright history cannot
// ghost into a uniform new frame.
TEST(Reprojection, MovingHistoryIsClampedToTheNeighbourhood) {
  TemporalReprojection r;
  GBuffer g = still_wall();
  FrameBuffer bright;
  bright.resize(kW, kH);
  std::fill(bright.rgba.begin(), bright.rgba.end(), 100.0f);
  r.accumulate(bright, g);
  for (size_t p = 0; p < g.pixels(); ++p) g.motion[2 * p] = 0.5f;
  FrameBuffer dim;
  dim.resize(kW, kH);
  std::fill(dim.rgba.begin(), dim.rgba.end(), 1.0f);
  r.accumulate(dim, g);
  EXPECT_NEAR(r.image().rgba[4 * (3 * kW + 4)], 1.0f, 1e-4);
}

// NaN and Inf samples never enter the history: the frames after them are finite and still converge
// to the average of the finite samples.
TEST(Reprojection, NonFiniteSamplesNeverEnterTheHistory) {
  TemporalReprojection r;
  const GBuffer g = still_wall();
  const float bad[] = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                       -std::numeric_limits<float>::infinity()};
  std::mt19937 rng(11);
  std::vector<double> sum(static_cast<size_t>(kW * kH * 4), 0.0);
  std::vector<int> good(static_cast<size_t>(kW * kH), 0);
  for (int n = 0; n < 16; ++n) {
    FrameBuffer f = noise_frame(rng);
    for (size_t p = 0; p < static_cast<size_t>(kW * kH); ++p) {
      // Every third pixel, every other frame, and the whole first row in frame 0 (no history yet).
      const bool poison = (p % 3 == static_cast<size_t>(n % 3) && n % 2 == 0) || (n == 0 && p < kW);
      if (poison) {
        f.rgba[4 * p + static_cast<size_t>(n % 3)] = bad[n % 3];
        continue;
      }
      for (int k = 0; k < 3; ++k) sum[4 * p + k] += f.rgba[4 * p + k];
      ++good[p];
    }
    r.accumulate(f, g);
    ASSERT_TRUE(all_finite(r.image())) << "frame " << n;
  }
  for (size_t p = 0; p < static_cast<size_t>(kW * kH); ++p)
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(r.image().rgba[4 * p + k], sum[4 * p + k] / good[p], 1e-3) << p;
}

// The same through RGB9E5 bands (kernel/band_pack.h), which have no NaN or infinity of their own: a
// non-finite sample is stored as the reserved word, decodes to NaN, and is rejected all the same; the
// history converges to the average of the finite samples as they were decoded.
TEST(Reprojection, NonFiniteSamplesThroughRgb9e5BandsNeverEnterTheHistory) {
  TemporalReprojection r;
  const GBuffer g = still_wall();
  const float bad[] = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                       -std::numeric_limits<float>::infinity()};
  std::mt19937 rng(13);
  std::vector<double> sum(static_cast<size_t>(kW * kH * 4), 0.0);
  std::vector<int> good(static_cast<size_t>(kW * kH), 0);
  BandBuffer band(kW, kH, BandFormat::rgb9e5);
  FrameBuffer decoded;
  decoded.resize(kW, kH);
  for (int n = 0; n < 16; ++n) {
    FrameBuffer f = noise_frame(rng);
    std::vector<bool> poisoned(static_cast<size_t>(kW * kH), false);
    for (size_t p = 0; p < static_cast<size_t>(kW * kH); ++p) {
      poisoned[p] = (p % 3 == static_cast<size_t>(n % 3) && n % 2 == 0) || (n == 0 && p < kW);
      if (poisoned[p]) f.rgba[4 * p + static_cast<size_t>(n % 3)] = bad[n % 3];
    }
    for (int y = 0; y < kH; ++y) band.store(y, 0, f.row(y), kW, static_cast<uint32_t>(n));
    band.copy_rows_to(decoded, 0, kH);
    for (size_t p = 0; p < static_cast<size_t>(kW * kH); ++p) {
      if (poisoned[p]) {
        for (int k = 0; k < 3; ++k) ASSERT_TRUE(std::isnan(decoded.rgba[4 * p + k])) << "pixel " << p;
        continue;
      }
      for (int k = 0; k < 3; ++k) sum[4 * p + k] += decoded.rgba[4 * p + k];
      ++good[p];
    }
    r.accumulate(decoded, g);
    ASSERT_TRUE(all_finite(r.image())) << "frame " << n;
  }
  for (size_t p = 0; p < static_cast<size_t>(kW * kH); ++p)
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(r.image().rgba[4 * p + k], sum[4 * p + k] / good[p], 1e-3) << p;
}

TEST(Reprojection, MismatchedGBufferIsRejected) {
  TemporalReprojection r;
  FrameBuffer f;
  f.resize(4, 4);
  GBuffer g;
  g.resize(4, 3);
  EXPECT_THROW(r.accumulate(f, g), std::invalid_argument);
}
