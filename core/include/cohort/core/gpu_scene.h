// Turns the scene model into the flat arrays tracers read (commit::TracerScene): BLASes for the static
// world and each model, instances, materials, textures (with mips), lights.
#pragma once

#include <memory>

#include "cohort/commit/tracer_scene.h"
#include "cohort/scene/scene.h"
#include "kernel/layout.h"

namespace cohort::core {

struct GpuSceneOptions {
  float light_scale = 2.0f;  // r_lightScale
};

// Conversions shared by the whole-scene compile and the per-frame updates from scene deltas.
KMaterial to_kmaterial(const scene::Material& material, const scene::Scene& scene);
KLight to_klight(const scene::Light& light, const scene::Scene& scene, const GpuSceneOptions& options = {});
void set_instance_transform(KInstance& instance, const glm::vec3& origin, const glm::mat3& axis);

// Compile the whole scene: one BLAS for the static world (all areas), one per mesh used by entities.
// blas_of_mesh[m] is the BLAS index of scene mesh m (K_NONE if unused).
struct CompiledScene {
  commit::TracerScene tracer_scene;
  std::vector<uint32_t> blas_of_mesh;
  uint32_t world_blas = K_NONE;
};
CompiledScene compile_scene(const scene::Scene& scene, const GpuSceneOptions& options = {});

}  // namespace cohort::core
