// What `cohort render` renders: a compiled scene from a scene pack or a map, plus where the player
// starts.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "cohort/commit/tracer_scene.h"
#include "cohort/scene/render_world.h"

namespace cohort::app {

struct RenderScene {
  std::string name;
  // A scene pack's compiled scene (its materials are fixed at the time it was packed)...
  std::shared_ptr<const commit::TracerScene> tracer_scene;
  // ... or a map's world, which core::WorldSync compiles and whose materials animate with time.
  std::shared_ptr<scene::RenderWorld> world;
  glm::vec3 player_start{0.0f};
  float player_yaw = 0.0f;
};

// A scene pack, or a map (disk path, game path or bare name; `bases` are extra game folders) loaded
// into a RenderWorld. Throws std::runtime_error (or scene::ParseError) with the reason when it cannot be used.
RenderScene load_render_scene(const std::string& path, const std::vector<std::string>& bases = {});

}  // namespace cohort::app
