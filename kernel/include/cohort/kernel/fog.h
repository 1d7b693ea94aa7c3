/* Fog and blend lights (doom3-content.md section 9): they light nothing; the integrator applies them
 * along its rays.
 * - Fog light: over the length L of a ray segment inside the light volume the segment's far end fades
 *   toward the fog colour by a = 1 - 0.982^b, b = 255 (64/63) L / D (the engine's `_fog` table), a = 1
 *   once L > D. The engine indexes the table by planar eye depth from the eye wherever it is; here the
 *   length is that of the ray inside the volume, so fog also thickens bounce rays and a camera outside
 *   the volume sees fog only where its rays cross it. The `_fogEnter` fade at the top plane is omitted.
 * - Blend light: a surface inside the volume is multiplied (`blend add`: added) by the light's colour x
 *   light image x falloff, after its lighting; in a path tracer that scales everything the surface
 *   reflects, so the path throughput is scaled. */
#ifndef COHORT_KERNEL_FOG_H
#define COHORT_KERNEL_FOG_H
#include "lights.h"

#define K_FOG_TABLE_BASE 0.982f

/* Fog opacity over a length inside the volume, for fog distance D. */
KFN float k_fog_opacity(float length, float distance) {
  if (!(length > 0.0f)) return 0.0f;
  if (length > distance) return 1.0f;
  float b = k_fmin(255.0f, 255.0f * (64.0f / 63.0f) * length / distance);
  return 1.0f - k_pow(K_FOG_TABLE_BASE, b);
}

/* Clip [*t0, *t1] to where a + b t >= 0. */
KFN void k_clip_half_space(float a, float b, float* t0, float* t1) {
  if (k_fabs(b) < 1e-12f) {
    if (a < 0.0f) *t1 = -1.0f;
    return;
  }
  float t = -a / b;
  if (b > 0.0f) *t0 = k_fmax(*t0, t);
  else *t1 = k_fmin(*t1, t);
}

KFN float k_plane_slope(KGLOBAL const float* plane, KVec3 d) {
  return plane[0] * d.x + plane[1] * d.y + plane[2] * d.z;
}

/* Length of the ray segment (0, tmax) inside the light volume 0 <= S, T <= Q, 0 <= F <= 1 (box lights
 * have Q = 1). K_INF for a ray that stays inside. */
KFN float k_light_volume_length(KGLOBAL const KLight* light, KVec3 org, KVec3 dir, float tmax) {
  float as = k_plane_eval(light->plane_s, org), bs = k_plane_slope(light->plane_s, dir);
  float at = k_plane_eval(light->plane_t, org), bt = k_plane_slope(light->plane_t, dir);
  float aq = k_plane_eval(light->plane_q, org), bq = k_plane_slope(light->plane_q, dir);
  float af = k_plane_eval(light->plane_f, org), bf = k_plane_slope(light->plane_f, dir);
  float t0 = 0.0f, t1 = tmax;
  k_clip_half_space(as, bs, &t0, &t1);
  k_clip_half_space(aq - as, bq - bs, &t0, &t1);
  k_clip_half_space(at, bt, &t0, &t1);
  k_clip_half_space(aq - at, bq - bt, &t0, &t1);
  k_clip_half_space(af, bf, &t0, &t1);
  k_clip_half_space(1.0f - af, -bf, &t0, &t1);
  if (!(t1 > t0)) return 0.0f;
  return t1 >= K_INF ? K_INF : t1 - t0;
}

/* Whether the segment (0, tmax) of a ray surely misses a box light's volume: it passes farther from the
 * light's origin than the volume's farthest corner (volume_reach, with a margin for the planes' rounding). A
 * cheap reject before k_light_volume_length's six clips: most of a map's rays never come near its fog
 * volumes. Projected lights (frusta) and lights without a reach: never. */
KFN int k_segment_misses_box_light(KGLOBAL const KLight* light, KVec3 org, KVec3 dir, float tmax) {
  if (light->type == K_LIGHT_PROJECTED || !(light->volume_reach > 0.0f)) return 0;
  float reach2 = light->volume_reach * light->volume_reach * 1.001f + 1e-2f;
  KVec3 oc = v3_sub(org, v3_load_g(light->origin));
  float dd = v3_dot(dir, dir);
  float t = dd > 0.0f ? -v3_dot(oc, dir) / dd : 0.0f;
  t = k_fmin(k_fmax(t, 0.0f), tmax);
  KVec3 nearest = v3_madd(oc, dir, t);
  return v3_dot(nearest, nearest) > reach2;
}

/* Fog along the segment (0, tmax) of a ray: adds the fog colour seen through it to *radiance and
 * leaves in *throughput what reaches the segment's end. */
KFN void k_apply_fog(const KSceneView* scene, KVec3 org, KVec3 dir, float tmax, KVec3* radiance, KVec3* throughput) {
  for (kuint i = scene->volume_light_begin; i < scene->volume_light_end; ++i) {
    KGLOBAL const KLight* light = &scene->lights[i];
    if (!(light->flags & K_LIGHT_FOG) || k_segment_misses_box_light(light, org, dir, tmax)) continue;
    float a = k_fog_opacity(k_light_volume_length(light, org, dir, tmax), light->fog_distance);
    if (a <= 0.0f) continue;
    *radiance = v3_add(*radiance, v3_mul(*throughput, v3_scale(v3_load_g(light->color), a)));
    *throughput = v3_scale(*throughput, 1.0f - a);
  }
}

KFN int k_light_volume_contains(KGLOBAL const KLight* light, KVec3 p) {
  float q = k_plane_eval(light->plane_q, p);
  if (q <= 0.0f) return 0;
  float s = k_plane_eval(light->plane_s, p), t = k_plane_eval(light->plane_t, p), f = k_plane_eval(light->plane_f, p);
  return s >= 0.0f && s <= q && t >= 0.0f && t <= q && f >= 0.0f && f <= 1.0f;
}

/* Blend lights at an opaque surface point: multiplies *throughput (filter) or adds to *radiance (add). */
KFN void k_apply_blend_lights(const KSceneView* scene, KVec3 p, KVec3* radiance, KVec3* throughput) {
  for (kuint i = scene->volume_light_begin; i < scene->volume_light_end; ++i) {
    KGLOBAL const KLight* light = &scene->lights[i];
    if (!(light->flags & K_LIGHT_BLEND) || !k_light_volume_contains(light, p)) continue;
    KVec3 factor = k_light_radiance_at(scene, light, p);
    if (light->flags & K_LIGHT_BLEND_ADD) *radiance = v3_add(*radiance, v3_mul(*throughput, factor));
    else *throughput = v3_mul(*throughput, factor);
  }
}

#endif
