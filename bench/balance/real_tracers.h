// The real tracers `cohort bench balance --real` measures (Embree, OpenCL, CUDA), each with the
// bundled test map (or the given scene) already applied.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "cohort/core/tracer.h"

namespace cohort::app {

struct RealTracers {
  std::vector<std::unique_ptr<core::Tracer>> tracers;
  glm::vec3 eye{0.0f};   // where the spinning camera stands: the scene's player start at eye height
  float yaw = 0.0f;      // the player start's view direction, degrees
};

// names: tracer specs as `--tracers` takes them ("embree", "opencl:0", "cuda:1", "all", ...).
// Throws std::runtime_error / std::invalid_argument saying what is missing.
RealTracers make_real_tracers(const std::vector<std::string>& names, const std::string& scene);

}  // namespace cohort::app
