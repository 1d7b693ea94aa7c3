#include "viewer/fly_camera.h"

#include <cmath>

#include <gtest/gtest.h>

namespace cohort::viewer {
namespace {

void expect_vec(const float* v, glm::vec3 expected, float tol = 1e-5f) {
  EXPECT_NEAR(v[0], expected.x, tol);
  EXPECT_NEAR(v[1], expected.y, tol);
  EXPECT_NEAR(v[2], expected.z, tol);
}

TEST(FlyCamera, YawZeroLooksDownPlusXWithZUp) {
  FlyCamera cam;
  const KCamera k = cam.to_kcamera(200, 100);
  expect_vec(k.forward, {1, 0, 0});
  expect_vec(k.right, {0, -1, 0});  // Doom 3: +Y is left when looking down +X
  expect_vec(k.up, {0, 0, 1});
  EXPECT_EQ(k.width, 200u);
  EXPECT_EQ(k.height, 100u);
  EXPECT_NEAR(k.tan_half_fov_x, 1.0f, 1e-5f);   // 90 degrees
  EXPECT_NEAR(k.tan_half_fov_y, 0.5f, 1e-5f);   // square pixels at 2:1
}

TEST(FlyCamera, YawTurnsTowardPlusYAndPositivePitchLooksDown) {
  FlyCamera cam;
  cam.yaw = 90.0f;
  const KCamera turned = cam.to_kcamera(10, 10);
  expect_vec(turned.forward, {0, 1, 0});
  cam.yaw = 0.0f;
  cam.pitch = 90.0f - 1e-3f;
  EXPECT_LT(cam.forward().z, -0.999f);
  cam.pitch = 30.0f;
  const glm::vec3 f = cam.forward(), r = cam.right(), u = cam.up();
  EXPECT_NEAR(glm::dot(f, r), 0.0f, 1e-5f);
  EXPECT_NEAR(glm::dot(f, u), 0.0f, 1e-5f);
  EXPECT_NEAR(glm::dot(glm::cross(r, f), u), 1.0f, 1e-5f);
  EXPECT_GT(u.z, 0.0f);
}

TEST(FlyCamera, MovesAlongViewAndWorldUpAtItsSpeed) {
  FlyCamera cam;
  cam.speed = 100.0f;
  cam.yaw = 90.0f;
  MoveInput forward;
  forward.forward = 1.0f;
  cam.update(forward, 0.5f);
  EXPECT_NEAR(cam.position.x, 0.0f, 1e-3f);
  EXPECT_NEAR(cam.position.y, 50.0f, 1e-3f);

  MoveInput up_fast;
  up_fast.up = 1.0f;
  up_fast.fast = true;
  cam.update(up_fast, 1.0f);
  EXPECT_NEAR(cam.position.z, 100.0f * cam.fast_factor, 1e-3f);

  // Diagonal input is normalised: no faster than straight.
  FlyCamera diag;
  diag.speed = 100.0f;
  MoveInput both;
  both.forward = 1.0f;
  both.right = 1.0f;
  diag.update(both, 1.0f);
  EXPECT_NEAR(glm::length(diag.position), 100.0f, 1e-3f);
}

TEST(FlyCamera, MouseTurnsAndPitchIsClamped) {
  FlyCamera cam;
  MoveInput look;
  look.look_dx = 100.0f;  // right
  look.look_dy = 10000.0f;  // far down
  cam.update(look, 0.0f);
  EXPECT_NEAR(cam.yaw, 360.0f - 100.0f * cam.mouse_degrees_per_pixel, 1e-3f);
  EXPECT_FLOAT_EQ(cam.pitch, 89.0f);
  EXPECT_GT(glm::dot(cam.right(), glm::vec3(0, -1, 0)), 0.9f);  // still roughly facing +X
}

TEST(FlyCamera, SpeedStepsAreBounded) {
  FlyCamera cam;
  cam.speed = 100.0f;
  cam.change_speed(1);
  EXPECT_NEAR(cam.speed, 125.0f, 1e-3f);
  cam.change_speed(-1000);
  EXPECT_GE(cam.speed, 8.0f);
}

TEST(FlyCamera, RoundTripsThroughRenderView) {
  FlyCamera cam;
  cam.position = {10, -20, 30};
  cam.yaw = 135.0f;
  cam.pitch = -20.0f;
  cam.fov_x = 75.0f;
  const scene::RenderView view = cam.to_render_view(320, 240, 1234);
  EXPECT_EQ(view.time_ms, 1234);
  const FlyCamera back = FlyCamera::from_render_view(view);
  EXPECT_NEAR(back.yaw, 135.0f, 1e-3f);
  EXPECT_NEAR(back.pitch, -20.0f, 1e-3f);
  EXPECT_NEAR(back.position.y, -20.0f, 1e-5f);
  const KCamera a = cam.to_kcamera(320, 240), b = core::make_camera(view, 320, 240);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(a.forward[i], b.forward[i], 1e-5f);
    EXPECT_NEAR(a.right[i], b.right[i], 1e-5f);
    EXPECT_NEAR(a.up[i], b.up[i], 1e-5f);
  }
  EXPECT_NEAR(a.tan_half_fov_y, b.tan_half_fov_y, 1e-5f);
}

}  // namespace
}  // namespace cohort::viewer
