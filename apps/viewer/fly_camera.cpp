#include "fly_camera.h"

#include <algorithm>
#include <cmath>

namespace cohort::viewer {
namespace {

constexpr float kDegToRad = 3.14159265358979f / 180.0f;
constexpr float kMaxPitch = 89.0f;

void store(float dst[3], const glm::vec3& v) {
  dst[0] = v.x;
  dst[1] = v.y;
  dst[2] = v.z;
}

KCamera make_kcamera(const glm::vec3& origin, const glm::vec3& forward, const glm::vec3& right,
                     const glm::vec3& up, float fov_x, float fov_y, int width, int height) {
  KCamera cam{};
  store(cam.origin, origin);
  store(cam.forward, forward);
  store(cam.right, right);
  store(cam.up, up);
  cam.tan_half_fov_x = std::tan(0.5f * fov_x * kDegToRad);
  cam.tan_half_fov_y = std::tan(0.5f * fov_y * kDegToRad);
  cam.width = static_cast<kuint>(width);
  cam.height = static_cast<kuint>(height);
  return cam;
}

}  // namespace

glm::vec3 FlyCamera::forward() const {
  const float y = yaw * kDegToRad, p = pitch * kDegToRad;
  return {std::cos(p) * std::cos(y), std::cos(p) * std::sin(y), -std::sin(p)};
}

glm::vec3 FlyCamera::right() const {
  const float y = yaw * kDegToRad;
  return {std::sin(y), -std::cos(y), 0.0f};
}

glm::vec3 FlyCamera::up() const { return glm::cross(right(), forward()); }

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
  return 2.0f * std::atan(std::tan(0.5f * fov_x * kDegToRad) / aspect) / kDegToRad;
}

KCamera FlyCamera::to_kcamera(int width, int height) const {
  const float aspect = static_cast<float>(width) / static_cast<float>(std::max(height, 1));
  return make_kcamera(position, forward(), right(), up(), fov_x, fov_y(aspect), width, height);
}

scene::RenderView FlyCamera::to_render_view(int width, int height, int time_ms) const {
  scene::RenderView view;
  view.origin = position;
  view.axis = glm::mat3(forward(), -right(), up());
  view.fov_x = fov_x;
  view.fov_y = fov_y(static_cast<float>(width) / static_cast<float>(std::max(height, 1)));
  view.time_ms = time_ms;
  return view;
}

FlyCamera FlyCamera::from_render_view(const scene::RenderView& view) {
  FlyCamera cam;
  cam.position = view.origin;
  const glm::vec3 f = glm::normalize(view.axis[0]);
  cam.yaw = std::atan2(f.y, f.x) / kDegToRad;
  if (cam.yaw < 0.0f) cam.yaw += 360.0f;
  cam.pitch = std::clamp(-std::asin(std::clamp(f.z, -1.0f, 1.0f)) / kDegToRad, -kMaxPitch, kMaxPitch);
  cam.fov_x = view.fov_x;
  return cam;
}

KCamera kcamera_from_view(const scene::RenderView& view, int width, int height) {
  const glm::vec3 forward = glm::normalize(view.axis[0]);
  const glm::vec3 right = -glm::normalize(view.axis[1]);
  const glm::vec3 up = glm::normalize(view.axis[2]);
  // The view's own fov_y was chosen for its aspect; keep fov_x and derive fov_y from the image so
  // pixels stay square whatever size is rendered.
  const float aspect = static_cast<float>(width) / static_cast<float>(std::max(height, 1));
  const float fov_y = 2.0f * std::atan(std::tan(0.5f * view.fov_x * kDegToRad) / aspect) / kDegToRad;
  return make_kcamera(view.origin, forward, right, up, view.fov_x, fov_y, width, height);
}

}  // namespace cohort::viewer
