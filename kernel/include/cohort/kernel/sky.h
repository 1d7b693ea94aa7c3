/* Sky surfaces (K_BLEND_SKY): a cube map read by the ray's direction, as the engine's `texgen skybox`
 * (tr_light.cpp R_SkyboxTexGen: vertex - eye, in the surface's model space) and `texgen wobbleSky`
 * (the same direction read against rotated axes) make it. A ray that reaches the sky sees the cube
 * and nothing behind it; docs/sky.md. */
#ifndef COHORT_KERNEL_SKY_H
#define COHORT_KERNEL_SKY_H
#include "material.h"

/* The OpenGL cube-map rule: the face of the major axis (0..5 = +X, -X, +Y, -Y, +Z, -Z) and (s, t) in
 * [0, 1] on it, t = 0 the face image's first stored row. */
KFN kuint k_cube_face(KVec3 d, float* s, float* t) {
  float ax = k_fabs(d.x), ay = k_fabs(d.y), az = k_fabs(d.z);
  kuint face;
  float sc, tc, ma;
  if (ax >= ay && ax >= az) {
    ma = ax;
    face = d.x > 0.0f ? 0u : 1u;
    sc = d.x > 0.0f ? -d.z : d.z;
    tc = -d.y;
  } else if (ay >= az) {
    ma = ay;
    face = d.y > 0.0f ? 2u : 3u;
    sc = d.x;
    tc = d.y > 0.0f ? d.z : -d.z;
  } else {
    ma = az;
    face = d.z > 0.0f ? 4u : 5u;
    sc = d.z > 0.0f ? d.x : -d.x;
    tc = -d.y;
  }
  if (!(ma > 0.0f)) {   /* a zero or NaN direction */
    *s = 0.5f;
    *t = 0.5f;
    return 0u;
  }
  *s = 0.5f * (sc / ma + 1.0f);
  *t = 0.5f * (tc / ma + 1.0f);
  return face;
}

/* A cube map's colour along d: first_face is its +X face's texture slot, the other five follow. Skies
 * and environment stages (environment.h) both read their cubes here. */
KFN KVec3 k_cube_sample(const KSceneView* scene, kuint first_face, KVec3 d) {
  float s, t;
  kuint face = k_cube_face(d, &s, &t);
  return v4_rgb(k_texture_sample(scene, first_face + face, s, t));
}

/* What a ray along dir sees on a sky surface of this instance: the stage colour times the cube. */
KFN KVec3 k_sky_radiance(const KSceneView* scene, kuint instance, kuint material, KVec3 dir) {
  KGLOBAL const KMaterial* m = &scene->materials[material];
  KVec3 colour = v3_load_g(m->emissive_color);
  if (m->emissive_tex == K_NONE) return colour;
  KVec3 d = xform_vector_g(scene->instances[instance].world_to_object, dir);
  KVec3 x = v3_load_g(m->tex_transform), y = v3_load_g(m->tex_transform + 3);
  KVec3 lookup = v3(v3_dot(d, x), v3_dot(d, y), v3_dot(d, v3_cross(x, y)));
  return v3_mul(colour, k_cube_sample(scene, m->emissive_tex, lookup));
}

#endif
