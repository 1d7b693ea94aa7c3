// compile_scene: the whole scene model to one TracerScene.
#include <stdexcept>
#include <string>

#include "cohort/core/bvh.h"
#include "cohort/core/gpu_scene.h"
#include "gpu_scene_textures.h"

namespace cohort::core {
namespace {

KVertex to_kvertex(const scene::Vertex& v) {
  KVertex k{};
  k.pos[0] = v.position.x; k.pos[1] = v.position.y; k.pos[2] = v.position.z;
  k.u = v.st.x; k.v = v.st.y;
  k.normal[0] = v.normal.x; k.normal[1] = v.normal.y; k.normal[2] = v.normal.z;
  k.tangent[0] = v.tangent.x; k.tangent[1] = v.tangent.y; k.tangent[2] = v.tangent.z;
  k.bitangent_sign = v.tangent.w < 0.0f ? -1.0f : 1.0f;
  return k;
}

// Appends the meshes' vertices and returns their triangles (absolute vertex indices).
std::vector<KTriangle> append_meshes(const scene::Scene& scene, const std::vector<int>& meshes,
                                     std::vector<KVertex>& vertices) {
  std::vector<KTriangle> triangles;
  const uint32_t fallback_material = default_material_index(scene);
  for (int mesh_index : meshes) {
    const scene::Mesh& mesh = scene.meshes.at(static_cast<size_t>(mesh_index));
    const uint32_t base = static_cast<uint32_t>(vertices.size());
    for (const scene::Vertex& v : mesh.vertices) vertices.push_back(to_kvertex(v));
    for (const scene::Surface& surface : mesh.surfaces) {
      uint32_t material = surface.material >= 0 && static_cast<size_t>(surface.material) < scene.materials.size()
                              ? static_cast<uint32_t>(surface.material)
                              : fallback_material;
      for (uint32_t i = 0; i + 2 < surface.index_count; i += 3) {
        uint32_t first = surface.first_index + i;
        if (static_cast<size_t>(first) + 2 >= mesh.indices.size()) {
          throw std::runtime_error("compile_scene: mesh '" + mesh.name + "' has a surface past its index array");
        }
        KTriangle t{};
        t.v0 = base + mesh.indices[first];
        t.v1 = base + mesh.indices[first + 1];
        t.v2 = base + mesh.indices[first + 2];
        if (mesh.indices[first] >= mesh.vertices.size() || mesh.indices[first + 1] >= mesh.vertices.size() ||
            mesh.indices[first + 2] >= mesh.vertices.size())
          throw std::runtime_error("compile_scene: mesh '" + mesh.name + "' indexes a vertex it does not have");
        t.material = material;
        triangles.push_back(t);
      }
    }
  }
  return triangles;
}

uint32_t add_blas(commit::TracerScene& ts, const std::vector<KTriangle>& triangles) {
  BlasBuild build = build_blas(ts.vertices, triangles);
  KBlas blas{};
  blas.node_offset = static_cast<uint32_t>(ts.blas_nodes.size());
  blas.node_count = static_cast<uint32_t>(build.nodes.size());
  blas.tri_offset = static_cast<uint32_t>(ts.triangles.size());
  blas.tri_count = static_cast<uint32_t>(build.triangles.size());
  ts.blas_nodes.insert(ts.blas_nodes.end(), build.nodes.begin(), build.nodes.end());
  ts.triangles.insert(ts.triangles.end(), build.triangles.begin(), build.triangles.end());
  ts.blases.push_back(blas);
  return static_cast<uint32_t>(ts.blases.size() - 1);
}

KMaterial default_material() {
  scene::Scene empty;
  scene::Material m;
  m.name = "_default";
  m.diffuse_color = glm::vec4(0.5f, 0.5f, 0.5f, 1.0f);
  return to_kmaterial(m, empty);
}

}  // namespace

void rebuild_tlas(commit::TracerScene& ts) {
  if (ts.instances.empty()) {
    ts.tlas_nodes.clear();
    return;
  }
  std::vector<KBvhNode> roots;
  roots.reserve(ts.blases.size());
  for (const KBlas& b : ts.blases) roots.push_back(ts.blas_nodes.at(b.node_offset));
  ts.tlas_nodes = build_tlas(ts.instances, roots);
}

CompiledScene compile_scene(const scene::Scene& scene, const GpuSceneOptions& options) {
  CompiledScene out;
  commit::TracerScene& ts = out.tracer_scene;
  out.blas_of_mesh.assign(scene.meshes.size(), K_NONE);

  std::vector<KTriangle> world = append_meshes(scene, scene.area_meshes, ts.vertices);
  if (!world.empty()) {
    out.world_blas = add_blas(ts, world);
    for (int m : scene.area_meshes) out.blas_of_mesh[static_cast<size_t>(m)] = out.world_blas;
    KInstance inst{};
    set_instance_transform(inst, glm::vec3(0.0f), glm::mat3(1.0f));
    inst.blas = out.world_blas;
    inst.mask = K_MASK_PRIMARY | K_MASK_SHADOW;
    inst.entity = K_NONE;
    inst.material_override = K_NONE;
    ts.instances.push_back(inst);
  }

  for (size_t e = 0; e < scene.entities.size(); ++e) {
    const scene::Entity& entity = scene.entities[e];
    if (entity.mesh < 0 || static_cast<size_t>(entity.mesh) >= scene.meshes.size()) continue;
    uint32_t& blas = out.blas_of_mesh[static_cast<size_t>(entity.mesh)];
    if (blas == K_NONE) {
      std::vector<KTriangle> tris = append_meshes(scene, {entity.mesh}, ts.vertices);
      if (tris.empty()) continue;
      blas = add_blas(ts, tris);
    }
    KInstance inst{};
    set_instance_transform(inst, entity.origin, entity.axis);
    inst.blas = blas;
    inst.mask = K_MASK_PRIMARY | (entity.no_shadows ? 0u : K_MASK_SHADOW);
    inst.entity = static_cast<uint32_t>(e);
    inst.material_override = K_NONE;
    ts.instances.push_back(inst);
  }
  rebuild_tlas(ts);

  ts.materials.reserve(scene.materials.size() + 1);
  for (const scene::Material& m : scene.materials) ts.materials.push_back(to_kmaterial(m, scene));
  ts.materials.push_back(default_material());

  compile_textures(scene, ts);
  for (const scene::Light& light : scene.lights) ts.lights.push_back(to_klight(light, scene, options));
  ts.camera = make_camera(scene.player_start + glm::vec3(0.0f, 0.0f, 68.0f), scene.player_yaw, 0.0f, 90.0f, 640, 360);
  return out;
}

}  // namespace cohort::core
