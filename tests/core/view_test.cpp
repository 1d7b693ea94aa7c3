#include "cohort/core/view.h"

#include <cmath>

#include <gtest/gtest.h>

#include "cohort/core/frame_defaults.h"

namespace cohort::core {
namespace {

void expect_vec(const float* v, glm::vec3 expected, float tol = 1e-5f) {
  EXPECT_NEAR(v[0], expected.x, tol);
  EXPECT_NEAR(v[1], expected.y, tol);
  EXPECT_NEAR(v[2], expected.z, tol);
}

TEST(View, YawZeroLooksDownPlusXWithZUpAndPlusYLeft) {
  const KCamera k = make_camera(glm::vec3(1, 2, 3), ViewAngles{}, 90.0f, 200, 100);
  expect_vec(k.origin, {1, 2, 3});
  expect_vec(k.forward, {1, 0, 0});
  expect_vec(k.right, {0, -1, 0});
  expect_vec(k.up, {0, 0, 1});
  EXPECT_FALSE(std::signbit(k.forward[2]));  // a level view is exactly level: +0, not -0
  EXPECT_EQ(k.width, 200u);
  EXPECT_EQ(k.height, 100u);
  EXPECT_NEAR(k.tan_half_fov_x, 1.0f, 1e-6f);
  EXPECT_NEAR(k.tan_half_fov_y, 0.5f, 1e-6f);  // square pixels at 2:1
}

TEST(View, YawTurnsTowardPlusYAndPositivePitchLooksDown) {
  expect_vec(make_camera({}, {90.0f, 0.0f}, 90.0f, 8, 8).forward, {0, 1, 0});
  const KCamera down = make_camera({}, {0.0f, 30.0f}, 90.0f, 8, 8);
  expect_vec(down.forward, {std::cos(glm::radians(30.0f)), 0, -0.5f});
  EXPECT_GT(down.up[2], 0.0f);
  EXPECT_GT(down.up[0], 0.0f);  // tipped forward with the view
  const glm::mat3 axis = view_axis({0.0f, 90.0f});
  EXPECT_NEAR(axis[0].z, -1.0f, 1e-6f);
  EXPECT_TRUE(std::isfinite(axis[1].y) && std::isfinite(axis[2].x));  // straight down still has a frame
}

TEST(View, AxisIsOrthonormalAndRightHanded) {
  for (float yaw : {0.0f, 37.0f, 181.0f, 300.0f})
    for (float pitch : {-80.0f, -10.0f, 0.0f, 45.0f}) {
      const glm::mat3 a = view_axis({yaw, pitch});
      EXPECT_NEAR(glm::dot(a[0], a[1]), 0.0f, 1e-5f);
      EXPECT_NEAR(glm::dot(a[0], a[2]), 0.0f, 1e-5f);
      EXPECT_NEAR(glm::dot(a[1], a[2]), 0.0f, 1e-5f);
      EXPECT_NEAR(glm::dot(glm::cross(a[0], a[1]), a[2]), 1.0f, 1e-5f);  // forward x left = up
      EXPECT_NEAR(a[1].z, 0.0f, 1e-6f);                                  // no roll
    }
}

TEST(View, AnglesRoundTripThroughTheAxis) {
  const ViewAngles back = view_angles(view_axis({215.0f, -25.0f}));
  EXPECT_NEAR(back.yaw, 215.0f, 1e-3f);
  EXPECT_NEAR(back.pitch, -25.0f, 1e-3f);
}

TEST(View, RenderViewCameraMatchesTheAnglesCamera) {
  scene::RenderView view;
  view.origin = {10, -20, 30};
  view.axis = view_axis({135.0f, -20.0f});
  view.fov_x = 75.0f;
  view.fov_y = 10.0f;  // ignored: pixels stay square for the image rendered
  const KCamera a = make_camera(view.origin, {135.0f, -20.0f}, 75.0f, 320, 240);
  const KCamera b = make_camera(view, 320, 240);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(a.forward[i], b.forward[i], 1e-6f);
    EXPECT_NEAR(a.right[i], b.right[i], 1e-6f);
    EXPECT_NEAR(a.up[i], b.up[i], 1e-6f);
  }
  EXPECT_FLOAT_EQ(a.tan_half_fov_y, b.tan_half_fov_y);
}

TEST(View, PlayerEyeIsAboveThePlayerStart) {
  scene::Scene s;
  s.player_start = {64, -32, 8};
  const glm::vec3 eye = player_eye(s);
  EXPECT_FLOAT_EQ(eye.x, 64.0f);
  EXPECT_FLOAT_EQ(eye.z, 8.0f + kPlayerEyeHeight);
}

TEST(FrameDefaults, PathTracingWithNeeAndOneBounceAndDoom3SpecularBoost) {
  const KFrameParams p = default_frame_params();
  EXPECT_EQ(p.mode, K_MODE_PATH);
  EXPECT_EQ(p.spp, 1u);
  EXPECT_EQ(p.max_bounces, 1u);
  EXPECT_EQ(p.light_samples, 1u);
  EXPECT_FLOAT_EQ(p.shadow_rr, 0.03f);
  EXPECT_EQ(p.light_sampling, K_LIGHTS_AUTO);
  EXPECT_EQ(p.emissive_samples, 1u);
  EXPECT_FLOAT_EQ(p.spec_boost, 2.0f);
  EXPECT_EQ(p.row_begin, p.row_end);  // no band until the balancer names one
}

TEST(FrameDefaults, LightSamplingNamesRoundTrip) {
  const std::vector<std::string>& names = light_sampling_names();
  ASSERT_EQ(names.size(), 7u);
  EXPECT_EQ(light_sampling_mode(names[0]), K_LIGHTS_TREE);
  EXPECT_EQ(light_sampling_mode("all"), K_LIGHTS_ALL);
  EXPECT_EQ(light_sampling_mode("every"), K_LIGHTS_EVERY);
  EXPECT_EQ(light_sampling_mode("gather"), K_LIGHTS_GATHER);
  EXPECT_EQ(light_sampling_mode(names[4]), K_LIGHTS_IN_RANGE);
  EXPECT_EQ(names[4], "in-range");
  EXPECT_EQ(light_sampling_mode("dense"), K_LIGHTS_DENSE);
  EXPECT_EQ(light_sampling_mode("auto"), K_LIGHTS_AUTO);
  EXPECT_THROW(light_sampling_mode("bvh"), std::invalid_argument);
  for (const std::string& name : names) EXPECT_EQ(light_sampling_name(light_sampling_mode(name)), name);
  EXPECT_THROW(light_sampling_name(7u), std::invalid_argument);
}

TEST(FrameDefaults, AuxRaysNamesRoundTrip) {
  const std::vector<std::string>& names = aux_rays_names();
  ASSERT_EQ(names.size(), 2u);
  EXPECT_EQ(aux_rays_mode(names[0]), K_AUX_CENTRE_RAY);
  EXPECT_EQ(aux_rays_mode(names[1]), K_AUX_PATH_FIRST_HIT);
  EXPECT_THROW(aux_rays_mode("center"), std::invalid_argument);
}

}  // namespace
}  // namespace cohort::core
