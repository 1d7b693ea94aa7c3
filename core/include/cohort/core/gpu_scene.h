// From the scene model to the flat arrays tracers read (commit::TracerScene): per-object conversions
// and the whole-world compile, which is WorldSync's first sync (world_sync.h).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "cohort/commit/tracer_scene.h"
#include "cohort/scene/render_world.h"
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

// Conversions from the scene model, used by WorldSync. KMaterial index = scene material index, with
// one default material right after the map's (default_material_index) for surfaces that name none.
KMaterial to_kmaterial(const scene::Material& material, const scene::Scene& scene);
// Light colour = light_scale x light stage colour x _color. KLight.center is the world-space point the
// light shines from (origin + axis * light_center); for parallel lights the unit direction toward the
// light (light_center rotated by the axis). extent: soft-shadow jitter radius in world units (parallel:
// tangent of the cone's half-angle), scaled by KFrameParams::soft_shadow_scale in the kernel.
// stage_color: the light shader's stage colour evaluated for this frame (WorldSync); null: as loaded.
KLight to_klight(const scene::Light& light, const scene::Scene& scene, const GpuSceneOptions& options = {},
                 const glm::vec3* stage_color = nullptr);
// Why a light cannot be rendered (zero or negative radius, a degenerate projection, a non-finite or huge
// origin, colour or axis, a volume that does not close), or nullopt when it can. WorldSync skips such
// lights with a warning naming them.
std::optional<std::string> light_defect(const scene::Light& light, const scene::Scene& scene,
                                        const GpuSceneOptions& options = {});
void set_instance_transform(KInstance& instance, const glm::vec3& origin, const glm::mat3& axis);
inline uint32_t default_material_index(const scene::Scene& scene) { return static_cast<uint32_t>(scene.materials.size()); }

// The scene model's vertex in the kernels' layout.
KVertex to_kvertex(const scene::Vertex& vertex);
// Appends the mesh's vertex colours to a colour pool, white for a mesh without them (Mesh::colors).
// Throws std::runtime_error naming the mesh when it has colours for some vertices but not all.
void append_vertex_colors(std::vector<KVertexColor>& pool, const scene::Mesh& mesh);

// The triangles of a mesh's surfaces with vertex indices offset by vertex_base, each with its
// surface's KMaterial index (material_index(surface.material)). Throws std::runtime_error naming the
// mesh when a surface runs past the index array or an index past the vertices.
template <typename MaterialIndex>
std::vector<KTriangle> mesh_triangles(const scene::Mesh& mesh, uint32_t vertex_base, MaterialIndex material_index);

// The TLAS over `instances` (reordered to leaf order) for the BLASes of `tracer_scene`.
std::vector<KBvhNode> build_scene_tlas(std::vector<KInstance>& instances, const commit::TracerScene& tracer_scene);
// refit_tlas over the scene's BLAS roots; returns the new SAH cost.
float refit_scene_tlas(const std::vector<KInstance>& instances, const commit::TracerScene& tracer_scene,
                       std::vector<KBvhNode>& tlas_nodes);

// The whole world as it stands, compiled for the tracers: what WorldSync holds after syncing from an
// empty world (compiling is that sync; there is no second path). One BLAS for the static world (all
// areas), one per model in use. blas_of_mesh[m] is the BLAS index of scene mesh m (K_NONE if unused).
struct CompiledScene {
  commit::TracerScene tracer_scene;
  std::vector<uint32_t> blas_of_mesh;
  uint32_t world_blas = K_NONE;
};
CompiledScene compile_scene(const scene::RenderWorld& world, const GpuSceneOptions& options = {});
// A loaded map: its entities and lights as a RenderWorld seeded from it holds them.
CompiledScene compile_scene(scene::Scene scene, const GpuSceneOptions& options = {});

template <typename MaterialIndex>
std::vector<KTriangle> mesh_triangles(const scene::Mesh& mesh, uint32_t vertex_base, MaterialIndex material_index) {
  std::vector<KTriangle> triangles;
  for (const scene::Surface& surface : mesh.surfaces) {
    const uint32_t material = material_index(surface.material);
    for (uint32_t i = 0; i + 2 < surface.index_count; i += 3) {
      const size_t first = size_t(surface.first_index) + i;
      if (first + 2 >= mesh.indices.size())
        throw std::runtime_error("mesh '" + mesh.name + "' has a surface past its index array");
      const uint32_t a = mesh.indices[first], b = mesh.indices[first + 1], c = mesh.indices[first + 2];
      if (a >= mesh.vertices.size() || b >= mesh.vertices.size() || c >= mesh.vertices.size())
        throw std::runtime_error("mesh '" + mesh.name + "' indexes a vertex it does not have");
      triangles.push_back({vertex_base + a, vertex_base + b, vertex_base + c, material});
    }
  }
  return triangles;
}

}  // namespace cohort::core
