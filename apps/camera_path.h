// Scripted cameras for `cohort render --camera-path`: spin in place at the player start, or orbit
// around it, slowly (to watch convergence) or fast (to stress it). A pose per frame index, so a run
// is reproducible and the balancer sees the same motion every time.
#pragma once

#include <string>

#include <glm/glm.hpp>

namespace cohort::app {

struct CameraPath {
  enum class Kind { spin, orbit } kind = Kind::spin;
  float degrees_per_frame = 2.0f;
  float orbit_radius = 96.0f;
};

struct CameraPose {
  glm::vec3 origin{0.0f};
  float yaw = 0.0f;    // degrees, Doom 3: 0 looks down +X, turning toward +Y
};

// "spin", "spin-slow", "spin-fast", "orbit", "orbit-slow", "orbit-fast"; throws std::invalid_argument
// listing them otherwise.
CameraPath parse_camera_path(const std::string& name);
// What parse_camera_path would throw for `name`, or "" when it is a path: the check of a --camera-path option.
std::string camera_path_error(const std::string& name);
// `eye` and `yaw` are where the path starts (the player start at eye height).
CameraPose camera_path_pose(const CameraPath& path, const glm::vec3& eye, float yaw, int frame);

}  // namespace cohort::app
