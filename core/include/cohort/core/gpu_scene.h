// Turns the scene model into the flat arrays tracers read (commit::TracerScene): BLASes for the static
// world and each model, instances, materials, textures (with mips), lights.
#pragma once

#include <cstdint>
#include <memory>

#include <glm/glm.hpp>

#include "cohort/commit/tracer_scene.h"
#include "cohort/scene/scene.h"
#include "cohort/kernel/layout.h"

namespace cohort::core {

struct GpuSceneOptions {
  float light_scale = 2.0f;  // r_lightScale
};

// Every scene image appears in TracerScene::textures once per use, all sharing one copy of the texels:
// slot = use * images.size() + image. Surface maps wrap (colour maps decode sRGB, normal maps are
// flagged K_TEX_NORMAL); light images clamp and decode sRGB; falloff images clamp and stay linear.
enum class TextureUse : uint32_t { Surface = 0, LightImage = 1, Falloff = 2 };
constexpr uint32_t kTextureUseCount = 3;
uint32_t texture_slot(int image, TextureUse use, const scene::Scene& scene);  // K_NONE for -1 or empty images

// Conversions shared by the whole-scene compile and the per-frame updates from scene deltas.
// KMaterial index = scene material index; compile_scene appends one default material after them
// (default_material_index) for triangles whose surface names none.
KMaterial to_kmaterial(const scene::Material& material, const scene::Scene& scene);
// Light colour = light_scale x light stage colour x _color. KLight.center is the world-space point the
// light shines from (origin + axis * light_center); for parallel lights the unit direction toward the
// light (light_center rotated by the axis). extent: soft-shadow jitter radius in world units (parallel:
// tangent of the cone's half-angle), scaled by KFrameParams::soft_shadow_scale in the kernel.
KLight to_klight(const scene::Light& light, const scene::Scene& scene, const GpuSceneOptions& options = {});
void set_instance_transform(KInstance& instance, const glm::vec3& origin, const glm::mat3& axis);
inline uint32_t default_material_index(const scene::Scene& scene) { return static_cast<uint32_t>(scene.materials.size()); }

// A Doom 3 view: looks down +X at yaw 0, Z up; yaw turns left (toward +Y), pitch looks up.
KCamera make_camera(const glm::vec3& origin, float yaw_degrees, float pitch_degrees, float fov_x_degrees, int width,
                    int height);

// Compile the whole scene: one BLAS for the static world (all areas), one per mesh used by entities.
// blas_of_mesh[m] is the BLAS index of scene mesh m (K_NONE if unused).
struct CompiledScene {
  commit::TracerScene tracer_scene;
  std::vector<uint32_t> blas_of_mesh;
  uint32_t world_blas = K_NONE;
};
CompiledScene compile_scene(const scene::Scene& scene, const GpuSceneOptions& options = {});

// Rebuilds tracer_scene.tlas_nodes (and reorders instances into leaf order) after instances changed.
void rebuild_tlas(commit::TracerScene& tracer_scene);

}  // namespace cohort::core
