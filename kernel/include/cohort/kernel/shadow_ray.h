/* A vertex's shadow rays as plain data (shadow_queue.h walks or queues them), and how many a vertex may
 * leave in a wavefront's slots: what the host needs to size a wavefront's scratch, without the walk. */
#ifndef COHORT_KERNEL_SHADOW_RAY_H
#define COHORT_KERNEL_SHADOW_RAY_H
#include "layout.h"
#include "vec.h"

/* A shadow ray of next-event estimation and what it brings its vertex when nothing blocks it
 * (shadow_queue.h), so that a wavefront tracer walks a vertex's shadow rays in a kernel of their own. */
typedef struct KShadowRay {
  KVec3 org;
  float tmax;        /* <= 0: visible without a walk (a light that casts no shadows, no room for a blocker) */
  KVec3 dir;
  kuint mask;        /* the ray's instance mask (k_shadow_ray_mask), K_SHADOW_RAY_EMISSIVE for the emissive sample */
  KVec3 value;       /* value * kept: added to the vertex's direct sum, or its emissive term, when visible */
  float kept;        /* the shadow roulette's factor where the integrator multiplies it in as it adds the sample
                      * (the light samples' average), 1 where the value already holds it: the same float
                      * operations, contracted or not, wherever the sample is added */
} KShadowRay;

#define K_SHADOW_RAY_EMISSIVE 0x80000000u

/* An opaque vertex's light while its shadow rays are out: it adds
 * `throughput * (base + direct [* direct_scale] + emissive)`, clamped to `clamp`, to the path's radiance,
 * the sums in the integrator's order of float additions (k_vertex_light_sum). */
typedef struct KVertexLight {
  KVec3 throughput;
  float clamp;          /* the firefly clamp after a bounce (<= 0: none) */
  KVec3 base;           /* emission and environment */
  float direct_scale;   /* 1 / light samples (0: `every`, unscaled) */
  KVec3 direct;         /* the visible light samples' values so far */
  kuint has_emissive;   /* emissive-triangle sampling ran at this vertex */
  KVec3 emissive;       /* the emissive sample's value once seen visible */
  kuint ray_count;      /* its shadow rays still out (in a wavefront's scratch) */
} KVertexLight;

/* Most shadow rays a vertex leaves in a wavefront's slots (light samples and the emissive sample). */
#define K_SHADOW_QUEUE_MAX 8u

/* The slots a vertex needs with these settings: its light samples' rays (`every`: one per light of the map;
 * gather: at most light_samples) and the emissive sample's; 0 (walk them as they come) past
 * K_SHADOW_QUEUE_MAX. */
KFN kuint k_shadow_queue_slots(const KFrameParams* params, kuint light_count, kuint emissive_count) {
  kuint rays = params->light_samples;
  if (params->light_samples == 0u || params->light_sampling == K_LIGHTS_EVERY) rays = light_count;
  if (params->emissive_samples > 0u && emissive_count > 0u) ++rays;
  return rays <= K_SHADOW_QUEUE_MAX ? rays : 0u;
}

#if defined(__cplusplus) && !defined(__CUDACC_RTC__)
static_assert(sizeof(KShadowRay) == 48, "KShadowRay layout");
static_assert(sizeof(KVertexLight) == 64, "KVertexLight layout");
#endif

#endif
