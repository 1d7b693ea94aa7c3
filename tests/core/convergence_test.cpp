#include <gtest/gtest.h>

#include <cmath>

#include "cohort/core/convergence.h"
#include "cohort/core/simulated_tracer.h"

using namespace cohort::core;

namespace {

FrameBuffer constant(int w, int h, float v) {
  FrameBuffer fb;
  fb.resize(w, h);
  std::fill(fb.rgba.begin(), fb.rgba.end(), v);
  return fb;
}

}  // namespace

TEST(Convergence, BlendIsALinearMix) {
  EXPECT_FLOAT_EQ(converge(2.0f, 4.0f, 0.25f), 2.5f);
  EXPECT_FLOAT_EQ(converge(2.0f, 4.0f, 1.0f), 4.0f);
  EXPECT_FLOAT_EQ(converge(2.0f, 4.0f, 0.0f), 2.0f);
}

TEST(Convergence, AStaticViewAveragesEveryFrame) {
  AdaptiveConvergence c;
  const KCamera cam = spin_camera(4, 2, 0.3);
  double sum = 0.0;
  for (int n = 0; n < 20; ++n) {
    const float v = static_cast<float>(n % 3);  // noisy samples 0,1,2,0,1,2,...
    sum += v;
    const double f = c.accumulate(cam, constant(4, 2, v));
    EXPECT_NEAR(f, 1.0 / (n + 1), 1e-12) << "frame " << n;
    EXPECT_NEAR(c.image().rgba[5], sum / (n + 1), 1e-5) << "frame " << n;
  }
}

TEST(Convergence, StaticAccumulationStopsAtMaxFrames) {
  ConvergenceOptions o;
  o.max_frames = 4;
  AdaptiveConvergence c(o);
  const KCamera cam = spin_camera(4, 2, 0.0);
  double f = 0.0;
  for (int n = 0; n < 10; ++n) f = c.next_factor(cam);
  EXPECT_DOUBLE_EQ(f, 0.25);
}

TEST(Convergence, CameraMotionRaisesFAboveTheFloor) {
  AdaptiveConvergence c;
  for (int n = 0; n < 50; ++n) c.next_factor(spin_camera(4, 2, 0.0));
  const double still = c.next_factor(spin_camera(4, 2, 0.0));
  EXPECT_LT(still, 0.03);
  const double slow_turn = c.next_factor(spin_camera(4, 2, 0.001));   // 0.06 degrees
  EXPECT_GE(slow_turn, 0.1);                                           // the floor
  const double fast_turn = c.next_factor(spin_camera(4, 2, 0.001 + 10.0 * 3.14159265 / 180.0));
  EXPECT_GT(fast_turn, slow_turn);
  EXPECT_LT(fast_turn, 1.0);
  KCamera moved = spin_camera(4, 2, 0.001 + 10.0 * 3.14159265 / 180.0);
  moved.origin[0] += 16.0f;
  EXPECT_GT(c.next_factor(moved), 0.1);
}

TEST(Convergence, CutsAndResolutionChangesReset) {
  AdaptiveConvergence c;
  for (int n = 0; n < 10; ++n) c.next_factor(spin_camera(4, 2, 0.0));
  EXPECT_DOUBLE_EQ(c.next_factor(spin_camera(4, 2, 1.0)), 1.0);  // 57 degrees in one frame
  KCamera teleported = spin_camera(4, 2, 1.0);
  teleported.origin[2] = 1000.0f;
  EXPECT_DOUBLE_EQ(c.next_factor(teleported), 1.0);
  teleported.width = 8;
  EXPECT_DOUBLE_EQ(c.next_factor(teleported), 1.0);
  EXPECT_LT(c.next_factor(teleported), 1.0);  // and accumulation starts again
}

TEST(Convergence, MovingObjectPixelsDoNotGhost) {
  AdaptiveConvergence c;
  const KCamera cam = spin_camera(2, 1, 0.0);
  for (int n = 0; n < 30; ++n) c.accumulate(cam, constant(2, 1, 0.0f));
  // A bright object appears in pixel 1; the mask marks it as moving.
  FrameBuffer fresh = constant(2, 1, 0.0f);
  for (int k = 0; k < 4; ++k) fresh.rgba[4 + static_cast<size_t>(k)] = 1.0f;
  const std::vector<float> mask{0.0f, 1.0f};
  c.accumulate(cam, fresh, &mask);
  EXPECT_NEAR(c.image().rgba[4], 0.5f, 1e-6);   // moving_object_f = 0.5
  EXPECT_FLOAT_EQ(c.image().rgba[0], 0.0f);
  const std::vector<float> wrong_size{1.0f};
  EXPECT_THROW(c.accumulate(cam, fresh, &wrong_size), std::invalid_argument);
}
