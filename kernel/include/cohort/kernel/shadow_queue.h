/* Where an opaque vertex's shadow rays wait (integrator.h's k_direct_lighting and k_emissive_lighting emit
 * them, k_path_hit_lit and k_path_vertex_end own the queue). A queue without slots walks each ray as it
 * comes: the megakernels and the host tracers. A wavefront tracer gives it a slot in memory for every ray a
 * vertex may emit (k_shadow_queue_slots; with more, it walks them as they come), leaves the rays there for a kernel
 * that only walks shadow rays, and finishes the vertex after them (integrator.h's k_vertex_light_sum).
 * Either way the visible values are added in emission order, so the image is the same bit for bit. Needs
 * k_trace_occluded (integrator.h's includer defines it). */
#ifndef COHORT_KERNEL_SHADOW_QUEUE_H
#define COHORT_KERNEL_SHADOW_QUEUE_H
#include "shadow_ray.h"

typedef struct KShadowQueue {
  KGLOBAL KShadowRay* rays;   /* slot k at rays[k * stride] */
  kuint stride;
  kuint capacity;             /* 0: no slots, each ray walked as it comes; else at least the rays a vertex
                               * emits (k_shadow_queue_slots): best a constant, so that the compiler keeps
                               * only one of the two ways in a kernel */
  kuint count;
} KShadowQueue;

/* A queue that walks each ray as it comes. */
KFN KShadowQueue k_shadow_queue_inline(void) {
  KShadowQueue q;
  q.rays = 0;
  q.stride = 0u;
  q.capacity = 0u;
  q.count = 0u;
  return q;
}

/* 1 when nothing blocks the shadow ray (walked unless its tmax says it need not be). */
KFN int k_shadow_ray_visible(KTraceCtx* ctx, const KShadowRay* ray) {
  return ray->tmax <= 0.0f ||
         !k_trace_occluded(ctx, ray->org, ray->dir, ray->tmax, ray->mask & ~K_SHADOW_RAY_EMISSIVE);
}

/* A visible shadow ray's value to its vertex. */
KFN void k_shadow_ray_add(KVertexLight* v, const KShadowRay* ray) {
  if (ray->mask & K_SHADOW_RAY_EMISSIVE) v->emissive = ray->value;   /* kept is 1 */
  else v->direct = v3_add(v->direct, v3_scale(ray->value, ray->kept));
}

/* One shadow ray walked: its value to the vertex when nothing blocks it. */
KFN void k_shadow_ray_resolve(KTraceCtx* ctx, KVertexLight* v, const KShadowRay* ray) {
  if (k_shadow_ray_visible(ctx, ray)) k_shadow_ray_add(v, ray);
}

/* A shadow ray of the vertex: into its slot, or walked now by a queue without slots. */
KFN void k_shadow_queue_push(KTraceCtx* ctx, KShadowQueue* q, KVertexLight* v, KShadowRay ray) {
  if (q->capacity > 0u) {
    q->rays[q->count * q->stride] = ray;
    ++q->count;
    v->ray_count = q->count;
    return;
  }
  k_shadow_ray_resolve(ctx, v, &ray);
}

#endif
