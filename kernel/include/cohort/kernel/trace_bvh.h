/* Ray tracing over the portable two-level BVH for tracers without a native ray tracing API (OpenCL,
 * CUDA, and the CPU-side scene queries): defines KTraceCtx, k_trace_closest and k_trace_occluded as
 * integrator.h expects, on top of bvh_traverse.h. Candidate hits go through K_SURFACE_TRANSMITTANCE
 * (default: k_hit_transmittance from material.h), so alpha tests, pass-through surfaces and noShadows
 * materials behave as under Embree's filter functions. Include this, then integrator.h. */
#ifndef COHORT_KERNEL_TRACE_BVH_H
#define COHORT_KERNEL_TRACE_BVH_H
#include "material.h"

#ifndef K_SURFACE_TRANSMITTANCE
#define K_SURFACE_TRANSMITTANCE(scene, instance, triangle, u, v, shadow_ray) \
  k_hit_transmittance(scene, instance, triangle, u, v, shadow_ray)
#endif

#define K_BVH_CONTEXT const KSceneView*
#define K_BVH_HIT_PASSES(scene, instance, triangle, u, v, shadow_ray) \
  K_SURFACE_TRANSMITTANCE(scene, instance, triangle, u, v, shadow_ray)
#include "bvh_traverse.h"

typedef struct KTraceCtx {
  KSceneView scene;
  kuint closest_rays, occlusion_rays;   /* counted per thread, for the rays/s benchmarks */
} KTraceCtx;

KFN KSceneRef k_trace_scene_ref(const KTraceCtx* ctx) {
  KSceneRef r;
#ifdef K_BVH_TRIANGLE_EDGES
  r.triangle_edges = ctx->scene.triangle_edges;
#else
  r.vertices = ctx->scene.vertices;
  r.triangles = ctx->scene.triangles;
#endif
  r.blas_nodes = ctx->scene.blas_nodes;
  r.blases = ctx->scene.blases;
  r.instances = ctx->scene.instances;
  r.tlas_nodes = ctx->scene.tlas_nodes;
  r.instance_count = ctx->scene.instance_count;
  r.tlas_node_count = ctx->scene.tlas_node_count;
  return r;
}

KFN int k_trace_closest(KTraceCtx* ctx, KVec3 org, KVec3 dir, float tmax, kuint ray_mask, KHit* hit) {
  ctx->closest_rays++;
  return k_bvh_closest(k_trace_scene_ref(ctx), &ctx->scene, org, dir, 0.0f, tmax, ray_mask, hit);
}

KFN int k_trace_occluded(KTraceCtx* ctx, KVec3 org, KVec3 dir, float tmax, kuint ray_mask) {
  ctx->occlusion_rays++;
  return k_bvh_any(k_trace_scene_ref(ctx), &ctx->scene, org, dir, 0.0f, tmax, ray_mask);
}

#endif
