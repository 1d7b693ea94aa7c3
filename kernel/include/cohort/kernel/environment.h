/* Environment cube-map stages: glass and chrome (`cubeMap NAME texgen reflect`, usually `blend add`)
 * and `texgen normal`. The engine draws them as an extra unlit pass over the surface
 * (draw_common.cpp RB_STD_T_RenderShaderPasses): TG_REFLECT_CUBE reads the cube by the view vector
 * reflected about the surface normal (the bump map's where the material has one) in world space;
 * TG_DIFFUSE_CUBE by the vertex normal as stored (model space). docs/sky.md, "Environment cube maps". */
#ifndef COHORT_KERNEL_ENVIRONMENT_H
#define COHORT_KERNEL_ENVIRONMENT_H
#include "sky.h"

/* The radiance an environment stage adds along a camera or bounce ray of direction dir that hits this
 * surface; zero for materials without one. normal: the shading normal (k_surface_eval's, bump-mapped
 * where there is a normal map); reflecting about it or its negation gives the same direction. */
KFN KVec3 k_environment_radiance(const KSceneView* scene, KHit hit, kuint material, KVec3 normal, KVec3 dir) {
  KGLOBAL const KMaterial* m = &scene->materials[material];
  if (m->env_tex1 == 0u) return v3s(0.0f);
  KVec3 lookup;
  if (m->flags & K_MAT_ENV_BY_NORMAL) {
    KTriangle tri = scene->triangles[hit.triangle];
    lookup = k_vertex_normal(&scene->vertices[tri.v0], &scene->vertices[tri.v1], &scene->vertices[tri.v2], hit.u,
                             hit.v);
  } else {
    lookup = v3_sub(dir, v3_scale(normal, 2.0f * v3_dot(dir, normal)));
  }
  return v3_mul(v3_load_g(m->env_color), k_cube_sample(scene, m->env_tex1 - 1u, lookup));
}

#endif
