#include "cohort/core/view.h"

#include <algorithm>
#include <cmath>

namespace cohort::core {
namespace {

void store(float* dst, const glm::vec3& v) {
  dst[0] = v.x;
  dst[1] = v.y;
  dst[2] = v.z;
}

KCamera camera_from_frame(const glm::vec3& origin, const glm::vec3& forward, const glm::vec3& right,
                          const glm::vec3& up, float fov_x_degrees, int width, int height) {
  KCamera cam{};
  store(cam.origin, origin);
  store(cam.forward, forward);
  store(cam.right, right);
  store(cam.up, up);
  cam.width = static_cast<uint32_t>(width);
  cam.height = static_cast<uint32_t>(height);
  cam.tan_half_fov_x = std::tan(0.5f * glm::radians(fov_x_degrees));
  cam.tan_half_fov_y = cam.tan_half_fov_x * static_cast<float>(height) / static_cast<float>(std::max(width, 1));
  return cam;
}

}  // namespace

glm::mat3 view_axis(const ViewAngles& angles) {
  // Elevation above the horizon; 0 - pitch (not -pitch) keeps a level view's forward.z at +0.
  const float yaw = glm::radians(angles.yaw), elevation = glm::radians(0.0f - angles.pitch);
  const glm::vec3 forward(std::cos(yaw) * std::cos(elevation), std::sin(yaw) * std::cos(elevation),
                          std::sin(elevation));
  glm::vec3 right = glm::normalize(glm::cross(forward, glm::vec3(0.0f, 0.0f, 1.0f)));
  if (!std::isfinite(right.x)) right = glm::vec3(0.0f, -1.0f, 0.0f);  // straight up or down: keep yaw 0's right
  return glm::mat3(forward, -right, glm::cross(right, forward));
}

ViewAngles view_angles(const glm::mat3& axis) {
  const glm::vec3 f = glm::normalize(axis[0]);
  ViewAngles angles;
  angles.yaw = glm::degrees(std::atan2(f.y, f.x));
  if (angles.yaw < 0.0f) angles.yaw += 360.0f;
  angles.pitch = -glm::degrees(std::asin(std::clamp(f.z, -1.0f, 1.0f)));
  return angles;
}

KCamera make_camera(const glm::vec3& origin, const ViewAngles& angles, float fov_x_degrees, int width, int height) {
  const glm::mat3 axis = view_axis(angles);
  return camera_from_frame(origin, axis[0], -axis[1], axis[2], fov_x_degrees, width, height);
}

KCamera make_camera(const scene::RenderView& view, int width, int height) {
  return camera_from_frame(view.origin, glm::normalize(view.axis[0]), -glm::normalize(view.axis[1]),
                           glm::normalize(view.axis[2]), view.fov_x, width, height);
}

glm::vec3 player_eye(const scene::Scene& scene) {
  return scene.player_start + glm::vec3(0.0f, 0.0f, kPlayerEyeHeight);
}

}  // namespace cohort::core
