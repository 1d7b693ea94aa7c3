// The id plane of a frame's G-buffer (entity handle + 1, 0 for the world, K_NONE on a miss) written as
// a 16-bit binary PGM, so that tools outside the renderer (bench/quality/bench_quality.py) can measure
// one object's pixels; and which entities moved between two frames of a replay.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "cohort/scene/render_world.h"

namespace cohort::app {

// PGM value of a miss; ids at or above it are written as kIdPlaneMiss - 1 (a scene with 65,534 entities).
constexpr uint16_t kIdPlaneMiss = 65535;

// Writes `id` (width * height values, row 0 at the top) as a binary PGM with maxval 65535 (big-endian).
// Throws std::runtime_error naming the file when it cannot be written.
void write_id_plane_pgm(const std::string& path, int width, int height, const std::vector<uint32_t>& id);

// Named map entities and the id the id plane gives them (handle + 1).
std::map<std::string, uint32_t> entity_plane_ids(const scene::RenderWorld& world);

// Remembers each entity def's placement (origin, axis, joints) and tells which changed since the last call.
class MovedEntities {
 public:
  // Names (or "#handle" for unnamed defs) of the defs whose placement differs from the last call's;
  // the first call reports none. A freed or added def counts as moved.
  std::vector<std::string> update(const scene::RenderWorld& world);

 private:
  struct Placement {
    glm::vec3 origin{0.0f};
    glm::mat3 axis{1.0f};
    std::vector<scene::JointTransform> joints;
    bool operator==(const Placement&) const = default;
  };
  std::optional<std::vector<std::optional<Placement>>> last_;
};

}  // namespace cohort::app
