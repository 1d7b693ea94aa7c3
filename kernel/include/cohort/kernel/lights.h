/* Doom 3 lights: every light is four world-space planes (S, T, Q, falloff). Point and parallel
 * lights are a box, projected lights a frustum; the light image is read at (S/Q, T/Q) and the falloff
 * image at (F, 0.5), zero outside. Without a falloff image a point light uses the windowed
 * (1 - (d/r)^2)^2 on the box's normalised distance, a projected light (1 - F^2)^2.
 * KLight.center is the world-space point the light shines from (parallel: the unit direction toward
 * the light); extent is the soft-shadow jitter radius (parallel: tangent of the half-angle). */
#ifndef COHORT_KERNEL_LIGHTS_H
#define COHORT_KERNEL_LIGHTS_H
#include "brdf.h"

#define K_AMBIENT_N_DOT_L 0.78f

KFN float k_plane_eval(KGLOBAL const float* plane, KVec3 p) {
  return plane[0] * p.x + plane[1] * p.y + plane[2] * p.z + plane[3];
}

KFN float k_window_falloff(float d2) {
  if (d2 >= 1.0f) return 0.0f;
  float w = 1.0f - d2;
  return w * w;
}

KFN int k_inside01(float x) { return x >= 0.0f && x <= 1.0f; }

/* Where p lies in the light's volume: its S and T coordinates (divided by Q for projected lights) and
 * F. Returns 0 when p lies outside the volume, where the light is zero. */
KFN int k_light_coords(KGLOBAL const KLight* light, KVec3 p, float* s, float* t, float* f) {
  *s = k_plane_eval(light->plane_s, p);
  *t = k_plane_eval(light->plane_t, p);
  *f = k_plane_eval(light->plane_f, p);
  if (light->type == K_LIGHT_PROJECTED) {
    float q = k_plane_eval(light->plane_q, p);
    if (q <= 0.0f) return 0;
    *s /= q;
    *t /= q;
  }
  return k_inside01(*s) && k_inside01(*t) && k_inside01(*f);
}

/* Light colour times attenuation at volume coordinates (k_light_coords) inside the volume: the falloff
 * and light images are read here. */
KFN KVec3 k_light_radiance_in(const KSceneView* scene, KGLOBAL const KLight* light, float s, float t, float f) {
  float atten = 1.0f;
  KVec3 tint = v3s(1.0f);
  if (light->falloff_tex != K_NONE) {
    atten = k_texture_sample(scene, light->falloff_tex, f, 0.5f).x;
  } else if (light->type == K_LIGHT_PROJECTED) {
    atten = k_window_falloff(f * f);
  } else if (light->type == K_LIGHT_POINT) {
    float ds = 2.0f * s - 1.0f, dt = 2.0f * t - 1.0f, df = 2.0f * f - 1.0f;
    atten = k_window_falloff(ds * ds + dt * dt + df * df);
  }
  if (atten <= 0.0f) return v3s(0.0f);
  if (light->light_tex != K_NONE) tint = v4_rgb(k_texture_sample(scene, light->light_tex, s, t));
  return v3_scale(v3_mul(v3_load_g(light->color), tint), atten);
}

/* Light colour times attenuation at p, before N.L and shadows. */
KFN KVec3 k_light_radiance_at(const KSceneView* scene, KGLOBAL const KLight* light, KVec3 p) {
  float s, t, f;
  if (!k_light_coords(light, p, &s, &t, &f)) return v3s(0.0f);
  return k_light_radiance_in(scene, light, s, t, f);
}

/* Direction from p toward the light's (unjittered) emission point and the distance to it. */
KFN KVec3 k_light_direction(KGLOBAL const KLight* light, KVec3 p, float* dist) {
  KVec3 c = v3_load_g(light->center);
  if (light->type == K_LIGHT_PARALLEL) {
    *dist = K_INF;
    return v3_normalize(c);
  }
  KVec3 d = v3_sub(c, p);
  *dist = v3_length(d);
  return *dist > 0.0f ? v3_scale(d, 1.0f / *dist) : v3(0.0f, 0.0f, 1.0f);
}

/* A shadow-ray direction jittered over the light's extent (a disk facing p) for soft shadows. */
KFN KVec3 k_light_jittered_direction(KGLOBAL const KLight* light, KVec3 p, float scale, float u1, float u2,
                                     float* dist) {
  float d0;
  KVec3 dir = k_light_direction(light, p, &d0);
  float radius = light->extent * scale;
  if (radius <= 0.0f) { *dist = d0; return dir; }
  float dx, dy;
  k_sample_disk(u1, u2, &dx, &dy);
  KFrame f = k_frame_from_normal(dir);
  if (light->type == K_LIGHT_PARALLEL) {
    *dist = K_INF;
    return v3_normalize(v3_add(dir, v3_add(v3_scale(f.t, dx * radius), v3_scale(f.b, dy * radius))));
  }
  KVec3 target = v3_add(v3_load_g(light->center), v3_add(v3_scale(f.t, dx * radius), v3_scale(f.b, dy * radius)));
  KVec3 d = v3_sub(target, p);
  *dist = v3_length(d);
  return *dist > 0.0f ? v3_scale(d, 1.0f / *dist) : dir;
}

/* Unshadowed reflected radiance from one light toward wo. Doom 3 lights a white surface facing a
 * light of colour c to exactly c (its interaction has no 1/pi), so a light's colour is read as
 * pi x the radiance it contributes through the Lambert term: Doom's brightness, physical BRDF. */
KFN KVec3 k_light_unshadowed(const KSceneView* scene, KGLOBAL const KLight* light, const KSurface* sf, KVec3 wo,
                             float spec_boost) {
  /* One exit: with a return per case, GCC (x86-64) merged the results through the stack and read x and y
   * back as one 8-byte load of two 4-byte stores, a store-forwarding stall on every call. */
  KVec3 value = v3s(0.0f);
  if (light->flags & K_LIGHT_VOLUME_EFFECT) {
    /* fog and blend lights: fog.h */
  } else if (light->flags & K_LIGHT_AMBIENT) {
    /* The engine's ambient interaction lights from the `_ambient` cube's constant tangent-space vector
     * (about (0, -0.77, 0.78)), no specular: a flat surface gets N.L = 0.78 whichever way it faces. */
    KVec3 radiance = v3_scale(k_light_radiance_at(scene, light, sf->position), K_PI);
    if (!(v3_max_component(radiance) <= 0.0f))
      value = v3_scale(v3_mul(radiance, k_brdf_eval_cos(sf, wo, sf->normal, 0.0f)), K_AMBIENT_N_DOT_L);
  } else {
    /* Outside the volume (plane tests), then behind the surface (k_brdf_eval_cos's own test): both known
     * before the falloff and light images are read, which the light tree's gather does for up to 16
     * lights a hit. */
    float s, t, f, dist;
    if (k_light_coords(light, sf->position, &s, &t, &f)) {
      KVec3 wi = k_light_direction(light, sf->position, &dist);
      if (!(v3_dot(sf->normal, wi) <= 0.0f || v3_dot(sf->geo_normal, wi) <= 0.0f)) {
        KVec3 radiance = v3_scale(k_light_radiance_in(scene, light, s, t, f), K_PI);
        float spec_scale = (light->flags & K_LIGHT_NO_SPECULAR) ? 0.0f : spec_boost;
        if (!(v3_max_component(radiance) <= 0.0f))
          value = v3_mul(radiance, k_brdf_eval_cos(sf, wo, wi, spec_scale));
      }
    }
  }
  return value;
}

#endif
