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

// How crowded the Doom 3 lights' volumes are: the mean, over the lights in the tree, of how many lights' boxes
// hold the centre of the light's own box (itself included), found by walking the tree. 0 without lights. A
// light's centre stands for the points it lights; the count is about what in-range weighs there: a few on
// Doom 3 maps (the large generated map 5.1, the test map 2.1), 8.0 / 18.1 / 21.4 / 70.1 in bench_scaling's
// 8 / 64 / 256 / 1,024-light rooms (3k triangles). O(lights x their overlap): computed by the tracers when
// their light tree changes (tracers::TracerBase), and by `cohort render` for stats.json.
float light_density(const commit::TracerScene& scene);

// Above this light_density, K_LIGHTS_AUTO is K_LIGHTS_DENSE, at or below it K_LIGHTS_IN_RANGE: between the
// Doom 3 maps' few and the bench rooms' many, where dense already costs less than in-range on the CPU (64
// lights: 59 against 81 ms a frame; docs/integrator.md, "Dense rooms").
constexpr float kDenseLightDensity = 16.0f;

// The light sampling a frame asked for, with K_LIGHTS_AUTO resolved by the scene's light_density: the mode
// itself for every other mode.
kuint resolve_light_sampling(kuint mode, float density);

}  // namespace cohort::core
