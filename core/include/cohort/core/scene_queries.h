// Single-ray queries for the game side (line of sight, picking), answered on the CPU from a frame's
// TracerScene snapshot (the previous frame's BVH) with the same traversal code the GPU tracers run, so
// the answers agree with what is on screen.
#pragma once

#include <memory>
#include <optional>

#include <glm/glm.hpp>

#include "cohort/commit/tracer_scene.h"

namespace cohort::core {

struct PickHit {
  float distance = 0.0f;
  glm::vec3 point{0.0f};
  uint32_t instance = K_NONE;   // index into the snapshot's instances
  uint32_t entity = K_NONE;     // the instance's entity handle (K_NONE: the static world)
  uint32_t triangle = K_NONE;
  uint32_t material = K_NONE;
};

class SceneQueries {
 public:
  explicit SceneQueries(std::shared_ptr<const commit::TracerScene> snapshot);

  // True when nothing that casts shadows blocks the segment from a to b (alpha-tested holes and
  // translucent surfaces let the line through, as they let light through).
  bool line_of_sight(const glm::vec3& a, const glm::vec3& b) const;
  // The nearest visible surface along the ray within max_distance.
  std::optional<PickHit> pick(const glm::vec3& origin, const glm::vec3& direction, float max_distance = 1e30f) const;

 private:
  std::shared_ptr<const commit::TracerScene> scene_;
};

}  // namespace cohort::core
