#include "embree_filters.h"

namespace cohort::tracers::embree_filters {

namespace {

// The cases in which k_hit_transmittance (kernel/material.h) can return more than 0, for any ray.
bool material_may_pass(const commit::TracerScene& scene, kuint material) {
  if (material >= scene.materials.size()) return true;  // let the filter see what this is
  const KMaterial& m = scene.materials[material];
  return (m.blend != K_BLEND_OPAQUE && m.blend != K_BLEND_SKY) ||
         (m.flags & (K_MAT_ALPHA_TEST | K_MAT_NO_SHADOWS | K_MAT_TRANSLUCENT | K_MAT_NO_SELF_SHADOW)) != 0u;
}

}  // namespace

std::vector<char> blases_with_passing_materials(const commit::TracerScene& scene) {
  std::vector<char> passing(scene.blases.size(), 0);
  for (size_t b = 0; b < scene.blases.size(); ++b) {
    const KBlas& blas = scene.blases[b];
    for (kuint t = blas.tri_offset; t < blas.tri_offset + blas.tri_count && t < scene.triangles.size(); ++t)
      if (material_may_pass(scene, scene.triangles[t].material)) {
        passing[b] = 1;
        break;
      }
  }
  return passing;
}

bool triangle_may_pass(const commit::TracerScene& scene, size_t t) {
  return t >= scene.triangles.size() || material_may_pass(scene, scene.triangles[t].material);
}

std::vector<char> blases_with_passing_overrides(const commit::TracerScene& scene, bool device_ray_masks) {
  return blases_needing_filters(scene, std::vector<char>(scene.blases.size(), 0), device_ray_masks);
}

std::vector<char> blases_needing_filters(const commit::TracerScene& scene, const std::vector<char>& own_materials,
                                         bool device_ray_masks) {
  if (!device_ray_masks) return std::vector<char>(scene.blases.size(), 1);
  std::vector<char> needs = own_materials;
  needs.resize(scene.blases.size(), 1);
  for (const KInstance& inst : scene.instances)
    if (inst.blas < needs.size() && inst.material_override != K_NONE && material_may_pass(scene, inst.material_override))
      needs[inst.blas] = 1;
  return needs;
}

}  // namespace cohort::tracers::embree_filters
