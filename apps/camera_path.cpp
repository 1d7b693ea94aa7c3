#include "camera_path.h"

#include <cmath>
#include <stdexcept>

namespace cohort::app {
namespace {

constexpr float kSlowDegrees = 2.0f;   // a full turn in 180 frames
constexpr float kFastDegrees = 12.0f;  // a full turn in 30 frames: large per-frame motion

}  // namespace

CameraPath parse_camera_path(const std::string& name) {
  CameraPath path;
  const std::string kind = name.substr(0, name.find('-'));
  const std::string speed = name.find('-') == std::string::npos ? "slow" : name.substr(name.find('-') + 1);
  if (kind == "spin") path.kind = CameraPath::Kind::spin;
  else if (kind == "orbit") path.kind = CameraPath::Kind::orbit;
  const bool known_speed = speed == "slow" || speed == "fast";
  if ((kind != "spin" && kind != "orbit") || !known_speed)
    throw std::invalid_argument("unknown camera path '" + name +
                                "' (known: spin, spin-slow, spin-fast, orbit, orbit-slow, orbit-fast)");
  path.degrees_per_frame = speed == "fast" ? kFastDegrees : kSlowDegrees;
  return path;
}

std::string camera_path_error(const std::string& name) {
  try {
    parse_camera_path(name);
    return std::string();
  } catch (const std::exception& e) {
    return std::string(e.what());
  }
}

CameraPose camera_path_pose(const CameraPath& path, const glm::vec3& eye, float yaw, int frame) {
  const float turned = yaw + path.degrees_per_frame * static_cast<float>(frame);
  CameraPose pose;
  if (path.kind == CameraPath::Kind::spin) {
    pose.origin = eye;
    pose.yaw = turned;
    return pose;
  }
  // On a circle around the start, always facing its centre (and the room beyond it).
  const float a = glm::radians(turned + 180.0f);
  pose.origin = eye + path.orbit_radius * glm::vec3(std::cos(a), std::sin(a), 0.0f);
  pose.yaw = turned;
  return pose;
}

}  // namespace cohort::app
