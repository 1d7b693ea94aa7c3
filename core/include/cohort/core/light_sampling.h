// What next-event estimation samples, derived from a TracerScene: the light node array (KLightNode) with
// the tree over the Doom 3 lights' finite volumes (kernel/light_tree.h) and the tree over the emissive
// triangles (kernel/emissive_tree.h), and the list of emissive triangles in world space
// (KEmissiveTriangle). WorldSync rebuilds them when lights, instances or materials change and sends
// them as whole-array commit records; a scene pack's are rebuilt on reading.
#pragma once

#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "cohort/commit/tracer_scene.h"
#include "cohort/kernel/layout.h"

namespace cohort::core {

struct LightBounds {
  glm::vec3 min{0.0f}, max{0.0f};
};

// The world-space box outside which the light is zero (k_light_radiance_at): the parallelepiped of a
// point or parallel light, the truncated frustum of a projected one. nullopt when its planes are not
// finite, degenerate (no volume), or do not close the volume (a falloff slab parallel to a frustum edge).
std::optional<LightBounds> light_bounds(const KLight& light);

// The light tree over `lights` (lights without bounds are left out and can never be picked): median
// splits along the longest axis of the lights' box centres, one light per leaf, children adjacent.
// Node 0 is the root; empty when no light has bounds. Deterministic for the same lights.
std::vector<KLightNode> build_light_tree(const std::vector<KLight>& lights);

// Every triangle of every primary-visible instance whose material (the instance's override, else the
// triangle's) has k_emitter_power_density > 0 and whose area is nonzero, sorted by (instance, triangle),
// with its power (area x power density). The triangles' `leaf` is set by build_light_nodes.
struct EmissiveList {
  std::vector<KEmissiveTriangle> triangles;
  std::vector<float> power;
};
EmissiveList list_emissive_triangles(const commit::TracerScene& scene);

// The light node array: build_light_tree(lights), then the emissive tree over `emissive` in its last
// 2E - 1 nodes (same median splits, one triangle per leaf; E = its triangle count). Sets the
// triangles' `leaf`.
std::vector<KLightNode> build_light_nodes(const std::vector<KLight>& lights, EmissiveList& emissive);

// The derived arrays of `scene` (light nodes, emissive triangles) rebuilt from its other arrays.
void rebuild_light_sampling(commit::TracerScene& scene);

}  // namespace cohort::core
