// The whole-world compile: WorldSync's first sync, taken out of it.
#include "cohort/core/bvh.h"
#include "cohort/core/gpu_scene.h"
#include "cohort/core/world_sync.h"

namespace cohort::core {

KVertex to_kvertex(const scene::Vertex& v) {
  KVertex k{};
  k.pos[0] = v.position.x; k.pos[1] = v.position.y; k.pos[2] = v.position.z;
  k.u = v.st.x; k.v = v.st.y;
  k.normal[0] = v.normal.x; k.normal[1] = v.normal.y; k.normal[2] = v.normal.z;
  k.tangent[0] = v.tangent.x; k.tangent[1] = v.tangent.y; k.tangent[2] = v.tangent.z;
  k.bitangent_sign = v.tangent.w < 0.0f ? -1.0f : 1.0f;
  return k;
}

void append_vertex_colors(std::vector<KVertexColor>& pool, const scene::Mesh& mesh) {
  if (mesh.colors.empty()) {
    pool.insert(pool.end(), mesh.vertices.size(), K_VERTEX_COLOR_WHITE);
    return;
  }
  if (mesh.colors.size() != mesh.vertices.size())
    throw std::runtime_error("mesh '" + mesh.name + "' has " + std::to_string(mesh.colors.size()) +
                             " vertex colours for " + std::to_string(mesh.vertices.size()) + " vertices");
  pool.insert(pool.end(), mesh.colors.begin(), mesh.colors.end());
}

namespace {

std::vector<KBvhNode> blas_roots(const commit::TracerScene& ts) {
  std::vector<KBvhNode> roots;
  roots.reserve(ts.blases.size());
  for (const KBlas& b : ts.blases) roots.push_back(ts.blas_nodes.at(b.node_offset));
  return roots;
}

}  // namespace

std::vector<KBvhNode> build_scene_tlas(std::vector<KInstance>& instances, const commit::TracerScene& ts) {
  if (instances.empty()) return {};
  return build_tlas(instances, blas_roots(ts));
}

float refit_scene_tlas(const std::vector<KInstance>& instances, const commit::TracerScene& ts,
                       std::vector<KBvhNode>& tlas_nodes) {
  return refit_tlas(instances, blas_roots(ts), tlas_nodes);
}

CompiledScene compile_scene(const scene::RenderWorld& world, const GpuSceneOptions& options) {
  WorldSyncOptions sync_options;
  sync_options.gpu = options;
  return WorldSync(world, sync_options).release();
}

CompiledScene compile_scene(scene::Scene scene, const GpuSceneOptions& options) {
  const scene::RenderWorld world(std::move(scene));
  return compile_scene(world, options);
}

}  // namespace cohort::core
