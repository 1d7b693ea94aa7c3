/* The geometric half of an emissive-triangle sample (integrator.h's k_emissive_lighting): a uniform point on
 * the picked triangle, the direction and density toward it, and the BRDF there; what the emitter's material
 * gives it (its emission) comes after, in k_emissive_lighting. Apart so that a tracer may compute it for many
 * vertices at once (the Embree tracer's wavefront, eight per instruction stream: tracers/embree_cpu's
 * embree_emissive_samples.h, the same operations in the same order per lane). */
#ifndef COHORT_KERNEL_EMISSIVE_SAMPLE_H
#define COHORT_KERNEL_EMISSIVE_SAMPLE_H
#include "brdf.h"
#include "emissive_tree.h"

typedef struct KEmissiveSample {
  KVec3 x;         /* the point on the emitter */
  KVec3 wi;        /* toward it from the vertex */
  KVec3 f;         /* k_brdf_eval_cos(sf, wo, wi, 1) */
  float bu, bv;    /* its barycentrics of p1 and p2 */
  float pdf;       /* per solid angle: pick * 2 / double area * dist^2 / cos on the emitter */
  kuint index;     /* the emissive triangle; K_NONE: no sample (no pick, or the point is rejected) */
} KEmissiveSample;

/* The sample toward a point of emissive triangle `index` (picked with probability `pick`) from u1, u2; 0 (and
 * out->index K_NONE) when it adds nothing whatever the emitter's material: a degenerate triangle, the point
 * at the vertex, at a grazing angle on the emitter, or where the BRDF is zero. */
KFN int k_emissive_sample_point(const KSceneView* scene, const KSurface* sf, KVec3 wo, kuint index, float pick,
                                float u1, float u2, KEmissiveSample* out) {
  out->index = K_NONE;
  if (index == K_NONE || !(pick > 0.0f)) return 0;
  KGLOBAL const KEmissiveTriangle* e = &scene->emissive[index];
  float su = k_sqrt(u1);
  float bu = su * (1.0f - u2), bv = su * u2;   /* barycentrics of p1 and p2 */
  KVec3 p0 = v3_load_g(e->p0), p1 = v3_load_g(e->p1), p2 = v3_load_g(e->p2);
  KVec3 x = v3_add(v3_scale(p0, 1.0f - bu - bv), v3_add(v3_scale(p1, bu), v3_scale(p2, bv)));
  KVec3 cr = v3_cross(v3_sub(p1, p0), v3_sub(p2, p0));
  float double_area = v3_length(cr);
  if (!(double_area > 0.0f)) return 0;
  KVec3 to_light = v3_sub(x, sf->position);
  float dist2 = v3_dot(to_light, to_light);
  if (!(dist2 > 0.0f)) return 0;
  float dist = k_sqrt(dist2);
  KVec3 wi = v3_scale(to_light, 1.0f / dist);
  float cos_light = k_fabs(v3_dot(cr, wi)) / double_area;   /* emitters shine from both faces */
  if (cos_light <= 1e-6f) return 0;
  KVec3 f = k_brdf_eval_cos(sf, wo, wi, 1.0f);
  if (v3_max_component(f) <= 0.0f) return 0;
  out->x = x;
  out->wi = wi;
  out->f = f;
  out->bu = bu;
  out->bv = bv;
  out->pdf = pick * 2.0f / double_area * dist2 / cos_light;
  out->index = index;
  return 1;
}

#endif
