#include "fly_camera.h"

#include <algorithm>
#include <cmath>

namespace cohort::viewer {
namespace {

constexpr float kMaxPitch = 89.0f;

}  // namespace

glm::vec3 FlyCamera::forward() const { return core::view_axis({yaw, pitch})[0]; }
glm::vec3 FlyCamera::right() const { return -core::view_axis({yaw, pitch})[1]; }
glm::vec3 FlyCamera::up() const { return core::view_axis({yaw, pitch})[2]; }

void FlyCamera::update(const MoveInput& input, float seconds) {
  yaw -= input.look_dx * mouse_degrees_per_pixel;
  yaw = std::fmod(yaw, 360.0f);
  if (yaw < 0.0f) yaw += 360.0f;
  pitch = std::clamp(pitch + input.look_dy * mouse_degrees_per_pixel, -kMaxPitch, kMaxPitch);

  glm::vec3 move = input.forward * forward() + input.right * right() + input.up * glm::vec3(0, 0, 1);
  const float len = glm::length(move);
  if (len > 1.0f) move /= len;  // diagonal flight is no faster than straight flight
  const float step = speed * (input.fast ? fast_factor : 1.0f) * seconds;
  position += move * step;
}

void FlyCamera::change_speed(int steps) {
  speed = std::clamp(speed * std::pow(1.25f, static_cast<float>(steps)), 8.0f, 20000.0f);
}

float FlyCamera::fov_y(float aspect) const {
  return glm::degrees(2.0f * std::atan(std::tan(0.5f * glm::radians(fov_x)) / aspect));
}

KCamera FlyCamera::to_kcamera(int width, int height) const {
  return core::make_camera(position, {yaw, pitch}, fov_x, width, height);
}

scene::RenderView FlyCamera::to_render_view(int width, int height, int time_ms) const {
  scene::RenderView view;
  view.origin = position;
  view.axis = core::view_axis({yaw, pitch});
  view.fov_x = fov_x;
  view.fov_y = fov_y(static_cast<float>(width) / static_cast<float>(std::max(height, 1)));
  view.time_ms = time_ms;
  return view;
}

FlyCamera FlyCamera::from_render_view(const scene::RenderView& view) {
  FlyCamera cam;
  cam.position = view.origin;
  const core::ViewAngles angles = core::view_angles(view.axis);
  cam.yaw = angles.yaw;
  cam.pitch = std::clamp(angles.pitch, -kMaxPitch, kMaxPitch);
  cam.fov_x = view.fov_x;
  return cam;
}

}  // namespace cohort::viewer
