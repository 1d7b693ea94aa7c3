// The emissive-triangle list and the one call that refreshes the derived light-sampling arrays.
#include <cmath>

#include "cohort/core/light_sampling.h"
#include "cohort/kernel/emitters.h"

namespace cohort::core {
namespace {

KVec3 to_world(const KInstance& instance, const KVertex& v) {
  return xform_point_g(instance.object_to_world, v3(v.pos[0], v.pos[1], v.pos[2]));
}

void store(float* dst, KVec3 v) {
  dst[0] = v.x;
  dst[1] = v.y;
  dst[2] = v.z;
}

}  // namespace

EmissiveList list_emissive_triangles(const commit::TracerScene& scene) {
  EmissiveList out;
  // Which materials emit, once, so the scan of every instance's triangles is a table lookup each.
  std::vector<float> density(scene.materials.size());
  bool any = false;
  for (size_t m = 0; m < density.size(); ++m) {
    density[m] = k_emitter_power_density(&scene.materials[m]);
    any |= density[m] > 0.0f;
  }
  if (!any) return out;
  for (uint32_t i = 0; i < scene.instances.size(); ++i) {
    const KInstance& inst = scene.instances[i];
    if (!(inst.mask & K_MASK_PRIMARY) || inst.blas >= scene.blases.size()) continue;
    const KBlas& blas = scene.blases[inst.blas];
    const float override_density =
        inst.material_override != K_NONE && inst.material_override < density.size() ? density[inst.material_override]
                                                                                      : 0.0f;
    if (inst.material_override != K_NONE && override_density <= 0.0f) continue;
    for (uint32_t t = blas.tri_offset; t < blas.tri_offset + blas.tri_count; ++t) {
      const KTriangle& tri = scene.triangles[t];
      const float d = inst.material_override != K_NONE ? override_density
                      : tri.material < density.size() ? density[tri.material]
                                                      : 0.0f;
      if (d <= 0.0f) continue;
      KEmissiveTriangle e{};
      const KVec3 p0 = to_world(inst, scene.vertices[tri.v0]), p1 = to_world(inst, scene.vertices[tri.v1]),
                  p2 = to_world(inst, scene.vertices[tri.v2]);
      const float power = 0.5f * k_triangle_double_area(p0, p1, p2) * d;
      if (!(power > 0.0f) || !std::isfinite(power)) continue;
      store(e.p0, p0);
      store(e.p1, p1);
      store(e.p2, p2);
      e.instance = i;
      e.triangle = t;
      e.leaf = K_NONE;
      out.triangles.push_back(e);
      out.power.push_back(power);
    }
  }
  return out;
}

void rebuild_light_sampling(commit::TracerScene& scene) {
  EmissiveList emissive = list_emissive_triangles(scene);
  scene.light_nodes = build_light_nodes(scene.lights, emissive);
  scene.emissive_triangles = std::move(emissive.triangles);
}

}  // namespace cohort::core
