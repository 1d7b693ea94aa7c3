#include "cohort/core/scene_queries.h"

#include "cohort/kernel/trace_bvh.h"

namespace cohort::core {
namespace {

KTraceCtx context_for(const commit::TracerScene& s) {
  KTraceCtx ctx{};
  ctx.scene.vertices = s.vertices.data();
  ctx.scene.vertex_colors = s.vertex_colors.data();
  ctx.scene.triangles = s.triangles.data();
  ctx.scene.blas_nodes = s.blas_nodes.data();
  ctx.scene.blases = s.blases.data();
  ctx.scene.instances = s.instances.data();
  ctx.scene.tlas_nodes = s.tlas_nodes.data();
  ctx.scene.materials = s.materials.data();
  ctx.scene.textures = s.textures.data();
  ctx.scene.texels = s.texels.data();
  ctx.scene.lights = s.lights.data();
  ctx.scene.instance_count = kuint(s.instances.size());
  ctx.scene.tlas_node_count = kuint(s.tlas_nodes.size());
  ctx.scene.light_count = kuint(s.lights.size());
  ctx.scene.volume_light_begin = 0u;
  ctx.scene.volume_light_end = kuint(s.lights.size());
  return ctx;
}

KVec3 to_k(const glm::vec3& v) { return v3(v.x, v.y, v.z); }

}  // namespace

SceneQueries::SceneQueries(std::shared_ptr<const commit::TracerScene> snapshot) : scene_(std::move(snapshot)) {}

bool SceneQueries::line_of_sight(const glm::vec3& a, const glm::vec3& b) const {
  glm::vec3 d = b - a;
  float length = glm::length(d);
  if (!(length > 0.0f)) return true;
  KTraceCtx ctx = context_for(*scene_);
  // Stop just short of b so that a surface point as target is not its own occluder.
  return !k_trace_occluded(&ctx, to_k(a), to_k(d / length), length * (1.0f - 1e-4f), K_MASK_SHADOW);
}

std::optional<PickHit> SceneQueries::pick(const glm::vec3& origin, const glm::vec3& direction,
                                          float max_distance) const {
  float length = glm::length(direction);
  if (!(length > 0.0f)) return std::nullopt;
  glm::vec3 dir = direction / length;
  KTraceCtx ctx = context_for(*scene_);
  KHit hit{};
  if (!k_trace_closest(&ctx, to_k(origin), to_k(dir), max_distance, K_MASK_PRIMARY, &hit)) return std::nullopt;
  PickHit out;
  out.distance = hit.t;
  out.point = origin + dir * hit.t;
  out.instance = hit.instance;
  out.entity = scene_->instances[hit.instance].entity;
  out.triangle = hit.triangle;
  out.material = scene_->triangles[hit.triangle].material;
  return out;
}

}  // namespace cohort::core
