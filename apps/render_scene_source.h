// What `cohort render` and the benches render: a compiled scene from a scene pack, or from a map once
// the scene loader can read one, plus where the player starts.
#pragma once

#include <memory>
#include <string>

#include <glm/glm.hpp>

#include "cohort/commit/tracer_scene.h"

namespace cohort::app {

struct RenderScene {
  std::string name;
  std::shared_ptr<const commit::TracerScene> tracer_scene;
  glm::vec3 player_start{0.0f};
  float player_yaw = 0.0f;
};

// Throws std::runtime_error with the reason when the file cannot be used.
RenderScene load_render_scene(const std::string& path);

}  // namespace cohort::app
